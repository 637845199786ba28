# call 1: PAIRS="old-1 mid-1 new-1" bash call.sh A; call 2: CODES="old mid" bash call.sh B; call 3: bash call3.sh
# old = f837ff2 (writes in the loop), mid = a8470e1 (writes beside the chunk, init during compile), new = HEAD
# Same-machine A/B of the loop's writes beside the next chunk: f837ff2 (old, trees/f837ff2) vs the working tree (new),
# each run from its own directory (python -m puts the working directory first on sys.path).
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
python -m compileall -q /tmp/site . > /dev/null 2>&1
export PYTHONPATH=/tmp/site PYTHONUNBUFFERED=1
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; git log -1 --format=%h; } > $OUT/device.txt
top=$PWD
run() {  # name code timeout command...
  local name=$1 code=$2 tt=$3; shift 3; local dir=$top; [ $code = old ] && dir=$top/trees/f837ff2; [ $code = mid ] && dir=$top/trees/a8470e1
  local s=$(date +%s.%N)
  (cd $dir && timeout $tt "$@" --run-dir /tmp/runs/$name > /tmp/log-$name.txt 2>&1); local rc=$?
  cat /tmp/log-$name.txt >> $OUT/log.txt
  echo "$name rc=$rc whole_s=$(python -c "print(round($(date +%s.%N)-$s,1))")" | tee -a $OUT/time.txt
  grep -E "compiled|done" /tmp/log-$name.txt | tee -a $OUT/time.txt
  { echo "# $name"; cat /tmp/runs/$name/metrics.jsonl /tmp/runs/$name/*/metrics.jsonl 2>/dev/null; } >> $OUT/metrics.txt
}
if [ "$1" = NONE ]; then :
elif [ "$1" = A ]; then
for pair in ${PAIRS:-old-1 mid-1 new-1}; do code=${pair%-*}
  run push-$pair $code 120 python -m splid_jax.train --env push --compile-cache=
done
else
for code in ${CODES-old new}; do  # HER, 5 seeds, 10 chunks of 50 cycles, a checkpoint after each
  run her5-$code $code 200 python -m splid_jax.sweep --env push --algo her --seed 2000 --seeds 5 --iterations 500 --compile-cache=
done
fi
