# x2 host under MPS. FIG=1: Figure 3 on Push at 100,000 episodes with the paper presets (issue 66).
# Always: SPLID's default, SPLID with exact verdicts, and HER (mrl) on Slide with table=edged at the 2 ms step,
# fresh 9900-9904 (issues 65, 66). FINAL=1 exports a run's latest checkpoint even when it has not finished.
# Each call runs until BUDGET seconds after its start; everything resumes on the same warm machine.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-540} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
pgrep -f nvidia-cuda-mps-control >/dev/null || nvidia-cuda-mps-control -d
W=/tmp/s2; mkdir -p $W
C="--compile-cache= --no-plot"
sweep() {  # NAME SEED ARGS...
  N=$1; S=$2; shift 2; [ -f $W/$N.done ] && return 0; left=$(( END - $(date +%s) )); [ $left -lt 90 ] && return 1
  if [ -d $W/$N ]; then A="--resume $W/$N"; else A="$* --seed $S --seeds 5 --run-dir $W/$N"; fi
  timeout -s TERM -k 60 $left python3 -m splid_jax.sweep $A $C >> $W/$N.log 2>&1
  rc=$?; echo "$N rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/$N.done; return $rc
}
fig() {
  [ -f $W/fig.done ] && return; left=$(( END - $(date +%s) )); [ $left -lt 120 ] && return
  if [ -d $W/fig3 ]; then A="--resume"; else A="--env push --episodes 100000 --set preset=paper --side-by-side"; fi
  timeout -s TERM -k 90 $left python3 -m splid_jax.figures fig3 $A --out $W/fig3 --compile-cache= --quiet >> $W/fig.log 2>&1
  rc=$?; echo "fig rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/fig.done
}
[ "${FIG:-0}" = 1 ] && fig &
# GPU 0: SPLID on the edged 2 ms Slide, then with exact verdicts;
# GPU 1: HER (mrl) on the edged 2 ms Slide (about 1,500 s alone)
E="--env slide --env-options table=edged,timestep=0.002,substeps=20"
( export CUDA_VISIBLE_DEVICES=0; sweep splid-edged 9900 $E --iterations 30 --checkpoint-every 5 || exit
  sweep exact-edged 9900 $E --iterations 30 --checkpoint-every 5 --relabel exact ) &
( export CUDA_VISIBLE_DEVICES=1 XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
  sweep her-edged 9900 $E --algo her --iterations 900 --eval-every 25 --checkpoint-every 10 --num-envs 16 \
    --her-compute-dtype bfloat16 ) &
wait
for N in splid-edged exact-edged her-edged; do  # a finished run's policies: SPLID's in one archive, HER's one a seed (8 files at most)
  { [ -f $W/$N.done ] || { [ "${FINAL:-0}" = 1 ] && [ -d $W/$N ]; }; } && [ ! -d $W/export/$N ] || continue
  timeout -k 5 120 python3 -m splid_jax.export $W/$N/sigma*-s* --out $W/export/$N > $W/export-$N.log 2>&1
  if [ $N != her-edged ]; then (cd /tmp && tar czf $OUT/$N.tgz s2/export/$N)
  else (cd /tmp && for d in s2/export/$N/*; do tar czf $OUT/$N-$(basename $d).tgz $d; done); fi
done
cd /tmp
find s2 -type f -not -path 's2/export/*'  \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' -o -name '*.csv' -o -name '*.png' \) \
  -not -path '*/checkpoints/*' -size -8M | tar czf $OUT/runs.tgz -T -
nvidia-smi -L; cat $W/times.txt; tail -n 5 $W/fig.log; for f in $W/*-edged.log; do echo "== $f"; tail -n 2 $f; done
