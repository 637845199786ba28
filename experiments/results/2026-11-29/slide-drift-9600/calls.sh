# Issue 65: SPLID's default and HER (mrl) trained on Slide with arm_drift=1.5, fresh seeds 9600-9604, one per GPU of
# a 2-GPU host at once; after SPLID its GPU trains Figure 3's paper SPLID on Push to 100,000 episodes (issue 66).
# Each call runs until BUDGET seconds after its start, stops with SIGTERM (runs checkpoint) and the next call on the
# same warm machine resumes; a finished sweep's five policies are exported and returned.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-560} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/p65; mkdir -p $W/export
C="--compile-cache= --no-plot"
sweep() {  # NAME ARGS...: start or resume one sweep, within the call's budget
  N=$1; shift; [ -f $W/$N.done ] && return; left=$(( END - $(date +%s) )); [ $left -lt 90 ] && return
  if [ -d $W/$N ]; then A="--resume $W/$N"; else A="$* --seed 9600 --seeds 5 --run-dir $W/$N"; fi
  timeout -s TERM -k 60 $left python3 -m splid_jax.sweep $A $C >> $W/$N.log 2>&1
  rc=$?; echo "$N rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/$N.done
}
exp() {  # NAME: export each seed's policy once and return it, one archive a seed
  N=$1; [ -f $W/$N.done ] && [ ! -d $W/export/$N ] || return
  timeout -k 5 120 python3 -m splid_jax.export $W/$N/sigma*-s* --out $W/export/$N > $W/export/$N.log 2>&1
  echo "export $N rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  (cd /tmp && for d in p65/export/$N/*; do [ -d "$d" ] && tar czf $OUT/$N-$(basename $d).tgz $d; done)
}
fig() {  # Figure 3's paper SPLID on Push, 100,000 episodes, resumed across calls
  [ -f $W/fig.done ] && return; left=$(( END - $(date +%s) )); [ $left -lt 120 ] && return
  if [ -d $W/fig3 ]; then A="--resume"; else A="--env push --episodes 100000 --set preset=paper --methods splid"; fi
  timeout -s TERM -k 60 $left python3 -m splid_jax.figures fig3 $A --out $W/fig3 --compile-cache= --quiet >> $W/fig.log 2>&1
  rc=$?; echo "fig rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/fig.done
}
O="--env slide --env-options arm_drift=1.5"
( export CUDA_VISIBLE_DEVICES=0; sweep splid $O --iterations 40 --checkpoint-every 5; exp splid; fig ) &
( export CUDA_VISIBLE_DEVICES=1 XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
  sweep her $O --algo her --iterations 1250 --eval-every 25 --checkpoint-every 10 --num-envs 16 \
    --her-compute-dtype bfloat16; exp her ) &
wait
cd /tmp
find p65 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' -o -name '*.csv' -o -name '*.png' \) \
  -not -path 'p65/export/*/*/*' -not -path '*/checkpoints/*' -size -4M | tar czf $OUT/runs.tgz -T -
nvidia-smi -L; cat $W/times.txt; for f in $W/*.log; do echo "== $f"; tail -n 3 $f; done
