# Issue 66: Slide's landing goals (--relabel land) against the default on tuning seeds 1000-1004, and land on
# fresh 9600-9604 (whose default ran on 2026-11-29); 30 iterations = 15,360 episodes; three programs under MPS on
# one GPU. Each call runs until BUDGET seconds after its start; the next call on the same warm machine resumes.
export PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-560} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
pgrep -f nvidia-cuda-mps-control >/dev/null || nvidia-cuda-mps-control -d
W=/tmp/land; mkdir -p $W
C="--compile-cache= --no-plot"
sweep() {  # NAME SEED ARGS...: start or resume one sweep, within the call's budget
  N=$1; S=$2; shift 2; [ -f $W/$N.done ] && return; left=$(( END - $(date +%s) )); [ $left -lt 90 ] && return
  if [ -d $W/$N ]; then A="--resume $W/$N"; else A="$* --seed $S --seeds 5 --run-dir $W/$N"; fi
  timeout -s TERM -k 60 $left python3 -m splid_jax.sweep $A $C >> $W/$N.log 2>&1
  rc=$?; echo "$N rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/$N.done
}
O="--env slide --iterations 30 --checkpoint-every 5"
sweep default-1000 1000 $O &
sweep land-1000 1000 $O --relabel land &
sweep land-9600 9600 $O --relabel land &
wait
cd /tmp
find land -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' \) -not -path '*/checkpoints/*' \
  -size -4M | tar czf $OUT/runs.tgz -T -
nvidia-smi -L; cat $W/times.txt; for f in $W/*.log; do echo "== $f"; tail -n 4 $f; done
