# x2 host under MPS: Figure 3 on Push at 100,000 episodes with the paper presets, all six methods side by side over
# both GPUs (issue 66), resumed across calls on one warm machine; each call stops BUDGET seconds after its start.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-540} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
pgrep -f nvidia-cuda-mps-control >/dev/null || nvidia-cuda-mps-control -d
W=/tmp/s3; mkdir -p $W
if [ ! -f $W/fig.done ]; then
  if [ -d $W/fig3 ]; then A="--resume"; else A="--env push --episodes 100000 --set preset=paper --side-by-side"; fi
  timeout -s TERM -k 90 $(( END - $(date +%s) )) python3 -m splid_jax.figures fig3 $A --out $W/fig3 \
    --quiet >> $W/fig.log 2>&1
  rc=$?; echo "fig rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/fig.done
fi
cd /tmp && find s3 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' -o -name '*.csv' \
  -o -name '*.png' \) -not -path '*/checkpoints/*' -size -8M | tar czf $OUT/fig3.tgz -T -
nvidia-smi -L; cat $W/times.txt; tail -n 5 $W/fig.log; tail -n 1 $W/fig3/logs/*.log 2>/dev/null

# ---- 2026-11-30: the four methods the calls above did not finish, side by side (BUDGET=540, twice) ----
# x2 host under MPS: the four methods that Figure 3 (paper presets, Push, 100,000 episodes) did not finish on
# 2026-11-29 (her, pchid, no-select, gcsl), side by side over both GPUs, resumed across calls on one warm machine;
# each call stops BUDGET seconds after its start (BUDGET=540 twice; about 1,000 s of training in all). Join on the CPU:
#   R=experiments/results/2026-11-29/fig3-push-100k-paper; mkdir /tmp/old && tar xJf $R/runs.tar.xz -C /tmp/old &&
#   cp $R/figure.json /tmp/old/ && python -m splid_jax.figures fig3 --merge /tmp/old NEW/s5/fig3 --replace --out DIR
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-540} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
pgrep -f nvidia-cuda-mps-control >/dev/null || nvidia-cuda-mps-control -d
W=/tmp/s5; mkdir -p $W
if [ ! -f $W/fig.done ]; then
  if [ -d $W/fig3 ]; then A="--resume"; else
    A="--env push --episodes 100000 --set preset=paper --side-by-side --methods her,pchid,no-select,gcsl"; fi
  timeout -s TERM -k 90 $(( END - $(date +%s) )) python3 -m splid_jax.figures fig3 $A --out $W/fig3 \
    --quiet >> $W/fig.log 2>&1
  rc=$?; echo "fig rc=$rc $(( $(date +%s) - T0 ))s" >> $W/times.txt; [ $rc = 0 ] && touch $W/fig.done
fi
cd /tmp && find s5 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' -o -name '*.csv' \
  -o -name '*.png' \) -not -path '*/checkpoints/*' -size -8M | tar czf $OUT/fig3.tgz -T -
nvidia-smi -L; cat $W/times.txt; tail -n 5 $W/fig.log; for f in $W/fig3/logs/*.log; do echo "$f: $(grep '^iter' $f | tail -1)"; done
