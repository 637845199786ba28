# call 1 (tuning seeds 1000-1004; BUDGET=560)
# x2 host under MPS: SPLID's Push default against held shares (a share of each cloning batch drawn from the held,
# zero-action pairs), tuning seeds 1000-1004, 80 iterations (10,000 episodes), 4 programs per GPU. Stops BUDGET s
# after its start.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-540} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
pgrep -f nvidia-cuda-mps-control >/dev/null || nvidia-cuda-mps-control -d
W=/tmp/s6; mkdir -p $W/arms
S="python3 -m splid_jax.sweep --env push --seeds 5 --seed 1000 --iterations 80 --checkpoint-every 0 --compile-cache= --no-plot"
arm() { g=$1; n=$2; shift 2; left=$(( END - $(date +%s) - 25 ))
  CUDA_VISIBLE_DEVICES=$g timeout -s TERM -k 10 $left $S --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1
  echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 hs0 & arm 0 hs0.1 --held-share 0.1 & arm 0 hs0.2 --held-share 0.2 & arm 0 hs0.4 --held-share 0.4 &
arm 1 hs0.05 --held-share 0.05 & arm 1 hs0.3 --held-share 0.3 & arm 1 hs0.6 --held-share 0.6 &
arm 1 hs0.2_sig01 --held-share 0.2 --sigma-end 0.1 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -not -path '*/checkpoints/*' \
  -size -4M | tar czf $OUT/arms.tgz -T - times.txt
nvidia-smi -L; cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; grep -v '^\s*$' $f | tail -n 2; done

# call 2 (seeds 7100-7104 and 9300-9304, which chose nothing; BUDGET=230)
# x2 host: SPLID's Push default against --held-share 0.2 (chosen on tuning seeds 1000-1004) on the seeds HER (mrl)
# was reported on (7100-7104 on GPU 0, 9300-9304 on GPU 1), one program per GPU (--vary), 80 iterations.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-230} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/s7; mkdir -p $W/arms
S="python3 -m splid_jax.sweep --env push --seeds 5 --iterations 80 --checkpoint-every 0 --compile-cache= --no-plot"
arm() { g=$1; n=$2; shift 2; left=$(( END - $(date +%s) - 12 ))
  CUDA_VISIBLE_DEVICES=$g timeout -s TERM -k 5 $left $S --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1
  echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 s7100 --seed 7100 --vary held_share=0,0.2 & arm 1 s9300 --seed 9300 --vary held_share=0,0.2 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/arms.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; grep -v '^\s*$' $f | tail -n 2; done
