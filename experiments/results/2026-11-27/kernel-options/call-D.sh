# Call D of 2026-11-27 (one H200, 16:39 UTC), at 6dbc6c7 with PickAndPlace's new defaults (the working tree then):
# Push's default command timed by phase (`experiments/command_phases.py`, run then from an equal script),
# PickAndPlace's new default against its old options, Slide with the solve kernel and kernel_envs=2048 again.
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
export PYTHONPATH=/tmp/site:$PWD PYTHONUNBUFFERED=1
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; git log -1 --format=%h; git status --short | head; } > $OUT/device-D.txt
train() {  # name timeout env options...
  local name=$1 tt=$2 env=$3; shift 3; local s=$(date +%s.%N)
  timeout $tt python -m splid_jax.train --env $env --compile-cache= --run-dir /tmp/runs/$name "$@" > $OUT/train-$name.txt 2>&1
  echo "$name rc=$? whole_s=$(python -c "print(round($(date +%s.%N)-$s,1))")" | tee -a $OUT/time.txt
  grep -E "compiled|done" $OUT/train-$name.txt | tee -a $OUT/time.txt; cp /tmp/runs/$name/metrics.jsonl $OUT/metrics-$name.jsonl
}
s=$(date +%s.%N)
timeout 150 python experiments/command_phases.py --env push --compile-cache= --run-dir /tmp/runs/push-probe > $OUT/probe-push.txt 2>&1
echo "probe rc=$? whole_s=$(python -c "print(round($(date +%s.%N)-$s,1))")" | tee -a $OUT/time.txt
grep -E "^\[|compiled|done" $OUT/probe-push.txt
train pnp-new 175 pick_and_place
train pnp-old 175 pick_and_place --env-options solver_loops=gpu-search,collision=mjx,kernel_envs=0
train slide-limit2 190 slide --env-options solver_loops=gpu-fused,kernel_envs=2048
