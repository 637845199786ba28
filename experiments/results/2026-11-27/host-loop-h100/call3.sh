# same H100 kind: Push command new(fixed: init beside the compile only) / mid / old, HER chunk on one seed, HER 5-seed sweep new
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
python -m compileall -q /tmp/site . > /dev/null 2>&1
export PYTHONPATH=/tmp/site PYTHONUNBUFFERED=1
source call.sh NONE 2>/dev/null  # defines run(); B-branch loop skipped by CODES=""
for pair in new-2 mid-2 old-2; do code=${pair%-*}
  run push-$pair $code 120 python -m splid_jax.train --env push --compile-cache=
done
s=$(date +%s); PYTHONPATH=/tmp/site:$PWD timeout 100 python experiments/stage_budget.py --env push --algos her --chunk-only --out $OUT/her-chunk.json >> $OUT/log.txt 2>&1; echo "her-chunk rc=$? s=$(( $(date +%s)-s ))" >> $OUT/time.txt
run her5-new new 170 python -m splid_jax.sweep --env push --algo her --seed 2000 --seeds 5 --iterations 500 --compile-cache=
