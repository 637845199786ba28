# HER chunk: HEAD (2c61f96: 4 warps, updates one batch at a time) / new default (1 warp, batches drawn at once) / new with 4 warps;
# Push default command new vs HEAD. Results in one tarball (the call returns 8 files at most).
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
python -m compileall -q /tmp/site . .dev/head > /dev/null 2>&1
export PYTHONPATH=/tmp/site PYTHONUNBUFFERED=1
R=/tmp/r34; rm -rf $R; mkdir -p $R
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; git log -1 --format=%h; } > $R/device.txt
top=$PWD
t() { local name=$1 code=$2 lim=$3; shift 3; local dir=$top; [ $code = head ] && dir=$top/.dev/head
  local s=$(date +%s.%N); (cd $dir && PYTHONPATH=/tmp/site:$dir timeout $lim "$@" > $R/$name.log 2>&1); local rc=$?
  echo "$name rc=$rc whole_s=$(python -c "print(round($(date +%s.%N)-$s,1))")" | tee -a $R/time.txt; }
t her-head head 100 python experiments/stage_budget.py --env push --algos her --chunk-only --label head --out $R/her-head.json
t her-new new 100 python experiments/stage_budget.py --env push --algos her --chunk-only --label new --out $R/her-new.json
t her-new-w4 new 100 python experiments/stage_budget.py --env push --algos her --chunk-only --env-options kernel_warps=4 --label new-w4 --out $R/her-new-w4.json
t push-new new 120 python -m splid_jax.train --env push --compile-cache= --run-dir /tmp/runs/p34-new
t push-head head 120 python -m splid_jax.train --env push --compile-cache= --run-dir /tmp/runs/p34-head
for n in p34-new p34-head; do echo "# $n"; cat /tmp/runs/$n/metrics.jsonl; done > $R/metrics.txt 2>/dev/null
grep -h "chunk:" $R/*.log | tee -a $R/time.txt; grep -h "compiled\|done" $R/push-*.log | tee -a $R/time.txt
cd /tmp && tar czf $OUT/r34.tgz r34
