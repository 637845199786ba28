# x2 host under MPS: SPLID's default and HER (mrl) on Slide's default task, fresh seeds SEED (issue 65).
# FINAL=1 exports a run's latest checkpoint even when it has not finished. Each call runs until BUDGET seconds after
# its start; everything resumes on the same warm machine.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-540} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
pgrep -f nvidia-cuda-mps-control >/dev/null || nvidia-cuda-mps-control -d
W=/tmp/s4; mkdir -p $W
C="--compile-cache= --no-plot"
sweep() {  # NAME SEED ARGS...
  N=$1; S=$2; shift 2; [ -f $W/$N.done ] && return 0; left=$(( END - $(date +%s) )); [ $left -lt 90 ] && return 1
  if [ -d $W/$N ]; then A="--resume $W/$N"; else A="$* --seed $S --seeds 5 --run-dir $W/$N"; fi
  timeout -s TERM -k 60 $left python3 -m splid_jax.sweep $A $C >> $W/$N.log 2>&1
  rc=$?; echo "$N rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/$N.done; return $rc
}
# GPU 0: SPLID's default on Slide's default task (the edged table at the 2 ms step, the hand leaning out) to its
# 70 iterations or the device time; GPU 1: HER (mrl) on the same task and fresh seeds SEED (10000: 10000-10004)
( export CUDA_VISIBLE_DEVICES=0; sweep splid ${SEED:-10000} --env slide --checkpoint-every 5 ) &
( export CUDA_VISIBLE_DEVICES=1 XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
  sweep her ${SEED:-10000} --env slide --algo her --iterations 900 --eval-every 25 --checkpoint-every 10 --num-envs 16 \
    --her-compute-dtype bfloat16 ) &
wait
for N in splid her; do  # a finished run's policies: SPLID's in one archive, HER's one a seed (8 files at most)
  { [ -f $W/$N.done ] || { [ "${FINAL:-0}" = 1 ] && [ -d $W/$N ]; }; } && [ ! -d $W/export/$N ] || continue
  timeout -k 5 120 python3 -m splid_jax.export $W/$N/sigma*-s* --out $W/export/$N > $W/export-$N.log 2>&1
  if [ $N != her ]; then (cd /tmp && tar czf $OUT/$N.tgz s4/export/$N)
  else (cd /tmp && for d in s4/export/$N/*; do tar czf $OUT/$N-$(basename $d).tgz $d; done); fi
done
cd /tmp
find s4 -type f -not -path 's4/export/*'  \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' -o -name '*.csv' -o -name '*.png' \) \
  -not -path '*/checkpoints/*' -size -8M | tar czf $OUT/runs.tgz -T -
nvidia-smi -L; cat $W/times.txt; for f in $W/splid.log $W/her.log; do echo "== $f"; tail -n 2 $f; done
