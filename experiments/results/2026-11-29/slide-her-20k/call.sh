# HER (mrl) on Slide (the default task: the reference's pads), seeds 9200-9204 vmapped in one process, to 20,000
# episodes (1,250 x 16) over several calls on one warm machine: PHASE=start, then PHASE=resume; each call stops its
# sweep with SIGTERM after STOP seconds (the loop checkpoints and exits 143) and returns the metrics so far.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s)
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
W=/tmp/hs20k; mkdir -p $W/export
nvidia-smi --query-gpu=timestamp,utilization.gpu,memory.used --format=csv -l 10 >> $W/gpu_use.csv 2>&1 &
if [ "$PHASE" = start ]; then
  timeout -s TERM -k 60 ${STOP:-530} python3 -m splid_jax.sweep --env slide --algo her --compile-cache= --no-plot \
    --iterations 1250 --eval-every 25 --checkpoint-every 10 --num-envs 16 --her-compute-dtype bfloat16 \
    --seed 9200 --seeds 5 --run-dir $W/run >> $W/run.log 2>&1
else
  timeout -s TERM -k 60 ${STOP:-530} python3 -m splid_jax.sweep --resume $W/run --compile-cache= --no-plot >> $W/run.log 2>&1
fi
echo "$PHASE rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
kill %1 2>/dev/null
if [ "$EXPORT" = 1 ]; then
  timeout -k 5 60 python3 -m splid_jax.export $W/run/sigma*-s* --out $W/export/her > $W/export.log 2>&1
  echo "export rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  (cd $W/export && tar czf $OUT/export-her.tgz her)
fi
cd /tmp
find hs20k -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' -o -name '*.csv' \) -not -path 'hs20k/export/*' -not -path '*/checkpoints/*' -size -4M | tar czf $OUT/runs.tgz -T -
du -sh $W/run; cat $W/times.txt; tail -n 5 $W/run.log; grep -h '"episodes"' $W/run/sigma*-s9200/metrics.jsonl 2>/dev/null | tail -n 2 | cut -c1-300
