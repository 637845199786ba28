# Call 3 (2 GPUs): Figure 3's other six methods (HER at OpenAI Baselines' settings among them), seeds 0-4, side by
# side under CUDA MPS: Push to 10,000 episodes on GPU 0, PickAndPlace to 12,000 on GPU 1.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/wd3; mkdir -p $W; T0=$(date +%s)
nvidia-smi -L > $W/gpus.txt; nvidia-cuda-mps-control -d && echo "mps started" >> $W/times.txt
O="python3 -m splid_jax.figures fig3 --methods splid,gcsl,pchid,her-baselines,es,no-select --side-by-side --set checkpoint_every=0 --compile-cache= --quiet"
(CUDA_VISIBLE_DEVICES=0 timeout -k 30 540 $O --env push --episodes 10000 --out $W/push-rest > $W/push-rest.log 2>&1; echo "push-rest rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
(CUDA_VISIBLE_DEVICES=1 timeout -k 30 540 $O --env pick_and_place --episodes 12000 --out $W/pnp-rest > $W/pnp-rest.log 2>&1; echo "pnp-rest rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
wait
find $W -name checkpoints -type d -prune -exec rm -rf {} +
cd /tmp && find wd3 -type f -size -8M | tar czf $OUT/d3.tgz -T -
cat $W/times.txt; for f in $W/*.log $W/*/logs/*.log; do echo "== $f"; tail -n 3 $f; done
