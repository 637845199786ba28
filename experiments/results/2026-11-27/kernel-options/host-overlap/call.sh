# Calls E (16:55 UTC) and F (17:02 UTC) of 2026-11-27, one H200 each: Push's default command from the code at
# 6dbc6c7 ("old", unpacked into old/) and from a working tree that built the initial state while XLA compiled
# and (E) dispatched the next chunk before writing a checkpoint, or (F) wrote each checkpoint in a thread beside
# the next chunk (tried-F.patch), "new"; E ran old, new, old, new, F new, old, new, old (this script).
# Bytecode compiled first (compileall), as a pip install does.
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
s=$(date +%s.%N); python -m compileall -q /tmp/site . > /dev/null 2>&1; echo "compileall $(python -c "print(round($(date +%s.%N)-$s,1))") s" | tee $OUT/time.txt
export PYTHONUNBUFFERED=1
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; git log -1 --format=%h; git status --short | grep -v experiments/results | head; } > $OUT/device-F.txt
for pair in new-1 old-1 new-2 old-2; do code=${pair%-*}; rep=${pair#*-}; {
  root=$PWD; [ $code = old ] && root=$PWD/old
  name=push-$code-$rep; s=$(date +%s.%N)
  PYTHONPATH=/tmp/site:$root timeout 115 python -m splid_jax.train --env push --compile-cache= --run-dir /tmp/runs/$name > /tmp/train-$name.txt 2>&1; rc=$?; cat /tmp/train-$name.txt >> $OUT/log.txt
  echo "$name rc=$rc whole_s=$(python -c "print(round($(date +%s.%N)-$s,1))")" | tee -a $OUT/time.txt
  grep -E "compiled|done" /tmp/train-$name.txt | tee -a $OUT/time.txt; cp /tmp/runs/$name/metrics.jsonl $OUT/metrics-$name.jsonl
}; done
