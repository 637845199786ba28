# Call 2 (2 GPUs): Figure 3's HER (mrl) parts, seeds 0-4, each alone on its GPU: Push to 10,000 episodes (GPU 0),
# PickAndPlace to 12,000 (GPU 1); 16 envs, bf16, cuBLAS GEMMs.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/wd2; mkdir -p $W; T0=$(date +%s)
nvidia-smi -L > $W/gpus.txt
H="python3 -m splid_jax.figures fig3 --methods her --set her.num_envs=16 --set her.her_options=compute_dtype=bfloat16 --set checkpoint_every=0 --compile-cache= --quiet"
F=--xla_gpu_enable_triton_gemm=false
(CUDA_VISIBLE_DEVICES=0 XLA_FLAGS=$F timeout -k 30 540 $H --env push --episodes 10000 --out $W/push-her > $W/push-her.log 2>&1; echo "push-her rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
(CUDA_VISIBLE_DEVICES=1 XLA_FLAGS=$F timeout -k 30 540 $H --env pick_and_place --episodes 12000 --out $W/pnp-her > $W/pnp-her.log 2>&1; echo "pnp-her rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
wait
find $W -name checkpoints -type d -prune -exec rm -rf {} +
cd /tmp && find wd2 -type f -size -8M | tar czf $OUT/d2.tgz -T -
cat $W/times.txt; for f in $W/*.log; do echo "== $f"; tail -n 4 $f; done
