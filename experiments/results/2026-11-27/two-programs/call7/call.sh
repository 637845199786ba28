# one machine: Push default command, base = the tree in trees/c4b9d4c vs the working tree
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
python -m compileall -q /tmp/site . > /dev/null 2>&1
export PYTHONPATH=/tmp/site PYTHONUNBUFFERED=1
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; git log -1 --format=%h; } > $OUT/device.txt
top=$PWD
run() {  # name code timeout command...
  local name=$1 code=$2 tt=$3; shift 3; local dir=$top; [ $code = base ] && dir=$top/trees/c4b9d4c
  local s=$(date +%s.%N)
  (cd $dir && timeout $tt "$@" --run-dir /tmp/runs/$name > /tmp/log-$name.txt 2>&1); local rc=$?
  cat /tmp/log-$name.txt >> $OUT/log.txt
  echo "$name rc=$rc whole_s=$(python -c "print(round($(date +%s.%N)-$s,1))")" | tee -a $OUT/time.txt
  grep -E "compiled|done" /tmp/log-$name.txt | tee -a $OUT/time.txt
  { echo "# $name"; cat /tmp/runs/$name/metrics.jsonl /tmp/runs/$name/*/metrics.jsonl 2>/dev/null; } >> $OUT/metrics.txt
}
for pair in ${PAIRS:-new-1 base-1 new-2 base-2}; do code=${pair%-*}
  run push-$pair $code 120 python -m splid_jax.train --env push --compile-cache=
done
