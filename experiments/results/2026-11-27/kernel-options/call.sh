# The three calls of 2026-11-27 on one H200 (driver 580.159.04, jax 0.11.2), 16:09 to 16:34 UTC, at 6dbc6c7:
# `OPT= TT=175 bash call.sh A|B|C` from the repository root (C ran with TT=175), the cp312 wheels of mujoco,
# mujoco-mjx and brax unpacked onto PYTHONPATH. A: Push's step at 16 envs with the Cholesky and constraint-row
# kernels, Push's command with them (and kernel_envs=2048) and with the limit alone against the default, HER's chunk.
# B: Slide's step at 8,192 envs with the solve kernel, with and without kernel_envs=2048; Slide's command so.
# C: the per-stage table (Push, SPLID and HER); PickAndPlace's command with the solve and contact kernels and
# kernel_envs=2048 against its default. A's logs beyond A/ are in A/call-A-output.txt (the call's printed tail).
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
export PYTHONPATH=/tmp/site:$PWD PYTHONUNBUFFERED=1
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; git log -1 --format=%h; } > $OUT/device-$1.txt
train() {  # name env options...
  local name=$1 env=$2; shift 2; local s=$(date +%s.%N)
  timeout ${TT:-280} python -m splid_jax.train --env $env --compile-cache= --run-dir /tmp/runs/$name "$@" > $OUT/train-$name.txt 2>&1
  echo "$name rc=$? whole_s=$(python -c "print(round($(date +%s.%N)-$s,1))")" | tee -a $OUT/time.txt
  grep -E "compiled|done" $OUT/train-$name.txt | tee -a $OUT/time.txt; cp /tmp/runs/$name/metrics.jsonl $OUT/metrics-$name.jsonl
}
K=cholesky=gpu-fused,constraint=gpu-fused,kernel_envs=2048
if [ "$1" = A ]; then
  timeout 150 python experiments/solver_paths.py --task push --batch 16 --steps 50 --variants "" cholesky=gpu-fused \
      constraint=gpu-fused cholesky=gpu-fused,constraint=gpu-fused --out $OUT/paths-push-16.json \
      > $OUT/paths-push-16.txt 2>&1; echo "push 16 rc=$?"; grep variant $OUT/paths-push-16.txt
  train push-kernels push --env-options $K
  train push-limit push --env-options kernel_envs=2048
  train push-default push
  for name in kernels default; do
    opt=""; [ $name = kernels ] && opt="--env-options $K"
    timeout 100 python experiments/stage_budget.py --env push --algos her --chunk-only --label $name \
        $opt --out $OUT/her-$name.json > $OUT/her-$name.txt 2>&1; echo "her $name rc=$?"; tail -1 $OUT/her-$name.txt
  done
elif [ "$1" = B ]; then
  for b in 8192; do
    timeout 100 python experiments/solver_paths.py --task slide --batch $b --steps 20 --variants "" \
        solver_loops=gpu-fused solver_loops=gpu-fused,kernel_envs=2048 --out $OUT/paths-slide-$b.json \
        > $OUT/paths-slide-$b.txt 2>&1; echo "slide $b rc=$?"; grep variant $OUT/paths-slide-$b.txt
  done
  train slide-limit slide --env-options solver_loops=gpu-fused,kernel_envs=2048
  train slide-default slide
else
  timeout 230 python experiments/stage_budget.py --env push --algos splid her $OPT --out $OUT/stage-push.json \
      > $OUT/stage-push.txt 2>&1; echo "stage rc=$?"; tail -20 $OUT/stage-push.txt
  train pnp-limit pick_and_place --env-options solver_loops=gpu-fused,collision=gpu-fused,kernel_envs=2048
  train pnp-default pick_and_place
fi
