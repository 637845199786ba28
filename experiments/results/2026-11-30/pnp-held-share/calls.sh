# x2 host under MPS: PickAndPlace's default (hold) against stop and stop with held shares, tuning seeds 1000-1004,
# 60 iterations of 256 envs (15,360 episodes), two programs per GPU. Stops BUDGET s after its start.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-540} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
pgrep -f nvidia-cuda-mps-control >/dev/null || nvidia-cuda-mps-control -d
W=/tmp/s9; mkdir -p $W/arms
S="python3 -m splid_jax.sweep --env pick_and_place --seeds 5 --seed 1000 --iterations 60 --checkpoint-every 0 --compile-cache= --no-plot"
arm() { g=$1; n=$2; shift 2; left=$(( END - $(date +%s) - 25 ))
  CUDA_VISIBLE_DEVICES=$g timeout -s TERM -k 10 $left $S --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1
  echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 hold & arm 0 stop --relabel stop & arm 1 stop_hs0.2 --relabel stop --held-share 0.2 &
arm 1 stop_hs0.4 --relabel stop --held-share 0.4 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -not -path '*/checkpoints/*' \
  -size -4M | tar czf $OUT/arms.tgz -T - times.txt
nvidia-smi -L; cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; grep -v '^\s*$' $f | tail -n 2; done
