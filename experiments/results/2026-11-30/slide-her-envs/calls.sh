# x2 host under MPS: HER (mrl) on Slide's default task, tuning seeds 1000-1004, 16 envs per iteration on GPU 0 against
# 64 on GPU 1 (the same update ratio, one gradient step per 2 transitions), evaluated every 320 episodes in both, so
# the curves meet at equal episodes (issue 63: Slide's 20,000 episodes fit one session only at more envs). Stops
# BUDGET s after its start.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-540} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
pgrep -f nvidia-cuda-mps-control >/dev/null || nvidia-cuda-mps-control -d
W=/tmp/s8; mkdir -p $W
C="--compile-cache= --no-plot --checkpoint-every 0"
sweep() {  # NAME ARGS...
  N=$1; shift; left=$(( END - $(date +%s) - 25 )); [ $left -lt 90 ] && return 1
  timeout -s TERM -k 20 $left python3 -m splid_jax.sweep $* --seed 1000 --seeds 5 --run-dir $W/$N $C >> $W/$N.log 2>&1
  echo "$N rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
}
H="--env slide --algo her --her-compute-dtype bfloat16"
( export CUDA_VISIBLE_DEVICES=0 XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
  sweep her16 $H --num-envs 16 --iterations 1260 --eval-every 20 ) &
( export CUDA_VISIBLE_DEVICES=1 XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
  sweep her64 $H --num-envs 64 --iterations 315 --eval-every 5 ) &
wait
cd /tmp && find s8 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' -o -name '*.csv' \) \
  -not -path '*/checkpoints/*' -size -8M | tar czf $OUT/runs.tgz -T -
nvidia-smi -L; cat $W/times.txt; for f in $W/*.log; do echo "== $f"; grep -v '^\s*$' $f | tail -n 3; done

# call 2, the same host warm, GPU 1 only: her64 resumed for 290 s
CUDA_VISIBLE_DEVICES=1 XLA_FLAGS=--xla_gpu_enable_triton_gemm=false timeout -s TERM -k 15 290 python3 -m splid_jax.sweep --resume /tmp/s8/her64
