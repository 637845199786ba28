# x2 host: GPU0 = Slide --relabel exact on tuning seeds 1000-1004 (issue 66), then SPLID's default at the 2 ms step on
# fresh 9800-9804 (issue 65); GPU1 = HER (mrl) at the 2 ms step on 9800-9804. Each call runs until BUDGET seconds after
# its start; runs checkpoint on SIGTERM and the next call on the same warm machine resumes them.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-540} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/s1; mkdir -p $W/export
C="--compile-cache= --no-plot"
sweep() {  # NAME SEED ARGS...
  N=$1; S=$2; shift 2; [ -f $W/$N.done ] && return 0; left=$(( END - $(date +%s) )); [ $left -lt 90 ] && return 1
  if [ -d $W/$N ]; then A="--resume $W/$N"; else A="$* --seed $S --seeds 5 --run-dir $W/$N"; fi
  timeout -s TERM -k 60 $left python3 -m splid_jax.sweep $A $C >> $W/$N.log 2>&1
  rc=$?; echo "$N rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/$N.done; return $rc
}
exp() {  # NAME: export a finished sweep's five policies once, one archive per learner
  N=$1; [ -d $W/$N ] && [ ! -d $W/export/$N ] || return
  timeout -k 5 120 python3 -m splid_jax.export $W/$N/sigma*-s* --out $W/export/$N > $W/export/$N.log 2>&1
  echo "export $N rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  (cd /tmp && tar czf $OUT/$N-export.tgz s1/export/$N)
}
S2="--env slide --env-options timestep=0.002,substeps=20"
( export CUDA_VISIBLE_DEVICES=0
  sweep exact-1000 1000 --env slide --iterations 30 --checkpoint-every 5 --relabel exact &&
  sweep splid2ms 9800 $S2 --iterations 30 --checkpoint-every 5; exp splid2ms ) &
( export CUDA_VISIBLE_DEVICES=1 XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
  sweep her2ms 9800 $S2 --algo her --iterations 950 --eval-every 25 --checkpoint-every 10 --num-envs 16 \
    --her-compute-dtype bfloat16; exp her2ms ) &
wait
cd /tmp
find s1 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' -o -name '*.csv' \) \
  -not -path 's1/export/*/*/*' -not -path '*/checkpoints/*' -size -4M | tar czf $OUT/runs.tgz -T -
nvidia-smi -L; cat $W/times.txt; for f in $W/*.log; do echo "== $f"; tail -n 3 $f; done
