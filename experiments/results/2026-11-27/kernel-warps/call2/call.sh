# kernel warps 1 (new default) vs 4 (Triton's default, the old program): solve alone, control step, HER and SPLID chunks
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
export PYTHONPATH=/tmp/site:$PWD PYTHONUNBUFFERED=1
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; git log -1 --format=%h; } > $OUT/device.txt
t() { local name=$1 lim=$2; shift 2; local s=$(date +%s); timeout $lim "$@" > $OUT/$name.log 2>&1; echo "$name rc=$? $(( $(date +%s)-s )) s" | tee -a $OUT/device.txt; }
t solve 170 python experiments/bench_fused_solver.py --task push --batch 16 125 6250 --warps 1 4 --out $OUT/solve.json
t step16 120 python experiments/solver_paths.py --task push --batch 16 --steps 50 --variants "" kernel_warps=4 --out $OUT/step16.json
t her-w1 110 python experiments/stage_budget.py --env push --algos her --chunk-only --out $OUT/her-w1.json
t her-w4 110 python experiments/stage_budget.py --env push --algos her --chunk-only --env-options kernel_warps=4 --label warps4 --out $OUT/her-w4.json
t splid-w1 130 python experiments/stage_budget.py --env push --algos splid --chunk-only --out $OUT/splid-w1.json
t splid-w4 130 python experiments/stage_budget.py --env push --algos splid --chunk-only --env-options kernel_warps=4 --label warps4 --out $OUT/splid-w4.json
grep -h "ms\b\|ms " $OUT/*.log | grep -v Warn | head -40
