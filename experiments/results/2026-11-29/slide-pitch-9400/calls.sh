# Issue 65: SPLID's default and HER (mrl) trained on Slide with the hand's pitch (hand_pitch=1), fresh seeds
# 9400-9404, both under MPS on one H200; PHASE=start then PHASE=resume on the same warm machine; each phase stops its
# sweeps with SIGTERM after STOP seconds (they checkpoint); EXPORT_SPLID=1 / EXPORT_HER=1 export each seed's policy.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s)
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/p65; mkdir -p $W/export
pgrep -f nvidia-cuda-mps-control >/dev/null || nvidia-cuda-mps-control -d
nvidia-smi --query-gpu=timestamp,utilization.gpu,memory.used --format=csv -l 10 >> $W/gpu_use.csv 2>&1 &
STOP=${STOP:-530}
C="--compile-cache= --no-plot"
splid() {
  if [ "$PHASE" = start ]; then
    timeout -s TERM -k 60 $STOP python3 -m splid_jax.sweep --env slide --env-options hand_pitch=1 --iterations 40 \
      --checkpoint-every 5 --seed 9400 --seeds 5 --run-dir $W/splid $C >> $W/splid.log 2>&1
  elif [ ! -f $W/splid.done ]; then
    timeout -s TERM -k 60 $STOP python3 -m splid_jax.sweep --resume $W/splid $C >> $W/splid.log 2>&1
  fi
  rc=$?; echo "splid $PHASE rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/splid.done
}
her() {
  if [ "$PHASE" = start ]; then
    XLA_FLAGS=--xla_gpu_enable_triton_gemm=false timeout -s TERM -k 60 $STOP python3 -m splid_jax.sweep --env slide \
      --algo her --env-options hand_pitch=1 --iterations 1250 --eval-every 25 --checkpoint-every 10 --num-envs 16 \
      --her-compute-dtype bfloat16 --seed 9400 --seeds 5 --run-dir $W/her $C >> $W/her.log 2>&1
  else
    XLA_FLAGS=--xla_gpu_enable_triton_gemm=false timeout -s TERM -k 60 $STOP python3 -m splid_jax.sweep \
      --resume $W/her $C >> $W/her.log 2>&1
  fi
  echo "her $PHASE rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
}
exp() {  # A: export each seed's policy and return it, one archive a seed
  A=$1; timeout -k 5 120 python3 -m splid_jax.export $W/$A/sigma*-s* --out $W/export/$A > $W/export/$A.log 2>&1
  echo "export $A rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  (cd /tmp && for d in p65/export/$A/*; do [ -d "$d" ] && tar czf $OUT/$A-$(basename $d).tgz $d; done)
}
splid & P1=$!; her & P2=$!
[ "$EXPORT_SPLID" = 1 ] && [ -f $W/splid.done ] && exp splid
wait $P1 $P2
kill %1 2>/dev/null
cd /tmp
[ "$EXPORT_HER" = 1 ] && exp her
find p65 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' -o -name '*.csv' \) -not -path 'p65/export/*/*/*' -not -path '*/checkpoints/*' -size -4M | tar czf $OUT/runs.tgz -T -
du -sh $W/splid $W/her; cat $W/times.txt; for f in $W/splid.log $W/her.log; do echo "== $f"; tail -n 3 $f; done
