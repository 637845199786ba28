# Call 4 (one H200): HER (mrl) on the pads at their corrected centres (finger=pads), fresh seeds 9200-9201 in one
# process, cut by its own timeout; then each seed's policy exported for the reference evaluation.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
W=/tmp/pc; mkdir -p $W/export; T0=$(date +%s)
timeout -k 20 215 python3 -m splid_jax.sweep --env slide --checkpoint-every 0 --compile-cache= --no-plot --seed 9200 \
  --seeds 2 --algo her --iterations 350 --num-envs 16 --her-compute-dtype bfloat16 \
  --env-options finger=pads,finger_table=1,drive=weld,gripper_mass=22 --run-dir $W/her > $W/her.log 2>&1
echo "her rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
timeout -k 5 30 python3 -m splid_jax.export $W/her/sigma*-s* --out $W/export/her > $W/export.log 2>&1
echo "export rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
rm -rf $W/her/checkpoints $W/her/*/checkpoints
cd /tmp
for d in pc/export/her/*; do [ -d "$d" ] && tar czf $OUT/her-$(basename $d).tgz $d; done
find pc -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' \) -not -path 'pc/export/*/*/*' -size -4M | tar czf $OUT/runs.tgz -T -
cat $W/times.txt; tail -n 3 $W/her.log; cat $W/export.log
