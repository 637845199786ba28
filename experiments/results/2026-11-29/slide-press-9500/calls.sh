# Issue 65: SPLID's default and HER (mrl) trained on Slide with press_share=1 (hand_pitch=1 is the default), fresh
# seeds 9500-9504, one after the other on one H200 (HER alone runs ~5x faster than beside SPLID). Each call runs
# until BUDGET seconds after its start, stops a sweep with SIGTERM (it checkpoints) and the next call on the same warm
# machine resumes it; a finished sweep's five policies are exported and returned.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-560} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/p65; mkdir -p $W/export
C="--compile-cache= --no-plot"
sweep() {  # NAME ARGS...: start or resume one sweep, within the call's budget
  N=$1; shift; [ -f $W/$N.done ] && return; left=$(( END - $(date +%s) )); [ $left -lt 90 ] && return
  if [ -d $W/$N ]; then A="--resume $W/$N"; else A="$* --seed 9500 --seeds 5 --run-dir $W/$N"; fi
  timeout -s TERM -k 60 $left python3 -m splid_jax.sweep $A $C >> $W/$N.log 2>&1
  rc=$?; echo "$N rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/$N.done
}
exp() {  # NAME: export each seed's policy once and return it, one archive a seed
  N=$1; [ -f $W/$N.done ] && [ ! -d $W/export/$N ] || return
  timeout -k 5 120 python3 -m splid_jax.export $W/$N/sigma*-s* --out $W/export/$N > $W/export/$N.log 2>&1
  echo "export $N rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  (cd /tmp && for d in p65/export/$N/*; do [ -d "$d" ] && tar czf $OUT/$N-$(basename $d).tgz $d; done)
}
O="--env slide --env-options press_share=1"
sweep splid $O --iterations 40 --checkpoint-every 5
exp splid
XLA_FLAGS=--xla_gpu_enable_triton_gemm=false sweep her $O --algo her --iterations 750 --eval-every 25 \
  --checkpoint-every 10 --num-envs 16 --her-compute-dtype bfloat16
exp her
cd /tmp
find p65 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' \) -not -path 'p65/export/*/*/*' \
  -not -path '*/checkpoints/*' -size -4M | tar czf $OUT/runs.tgz -T -
cat $W/times.txt; for f in $W/*.log; do echo "== $f"; tail -n 3 $f; done
