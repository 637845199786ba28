# HER (mrl) on Slide with the reference's pads (the intended Slide default), fresh seeds 9200-9204 vmapped in one
# process toward 14,000 episodes (875 x 16), cut by its own timeout; each seed's policy exported; GPU use sampled.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
W=/tmp/h14; mkdir -p $W/arms $W/export; T0=$(date +%s)
OPTS=finger=pads,finger_table=1,drive=weld,gripper_mass=22
nvidia-smi --query-gpu=timestamp,utilization.gpu,memory.used --format=csv -l 10 > $W/gpu_use.csv 2>&1 &
timeout -k 60 ${STOP:-505} python3 -m splid_jax.sweep --env slide --algo her --checkpoint-every 0 --compile-cache= --no-plot \
  --iterations 875 --num-envs 16 --her-compute-dtype bfloat16 --seed 9200 --seeds 5 --env-options $OPTS \
  --run-dir $W/arms/a > $W/arms/a.log 2>&1
echo "a rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
timeout -k 5 50 python3 -m splid_jax.export $W/arms/a/sigma*-s* --out $W/export/a > $W/export/a.log 2>&1
echo "export a rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
kill %1 2>/dev/null
rm -rf $W/arms/*/checkpoints $W/arms/*/*/checkpoints 2>/dev/null
cd /tmp
for d in h14/export/*/*; do [ -d "$d" ] && tar czf $OUT/$(basename $d).tgz $d; done
find h14 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' -o -name '*.csv' \) -not -path 'h14/export/*/*/*' -size -4M | tar czf $OUT/runs.tgz -T -
ls -la $OUT; cat $W/times.txt; tail -n 4 $W/arms/a.log $W/export/a.log; tail -n 3 $W/gpu_use.csv
