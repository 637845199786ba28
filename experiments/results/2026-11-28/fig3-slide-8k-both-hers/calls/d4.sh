# Call 4 (2 GPUs): Figure 3 on Slide (the standard task) at 8,000 episodes with both HERs, seeds 0-4, cut by the
# session's device time: HER (mrl) alone on GPU 0 (16 envs, bf16, cuBLAS products); the other six methods side by side
# under CUDA MPS on GPU 1.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/wd4; mkdir -p $W; T0=$(date +%s)
nvidia-smi -L > $W/gpus.txt; nvidia-cuda-mps-control -d && echo "mps started" >> $W/times.txt
H="python3 -m splid_jax.figures fig3 --env slide --episodes 8000 --set checkpoint_every=0 --compile-cache= --quiet"
F=--xla_gpu_enable_triton_gemm=false
(CUDA_VISIBLE_DEVICES=0 XLA_FLAGS=$F timeout -k 10 $1 $H --methods her --set her.num_envs=16 --set her.her_options=compute_dtype=bfloat16 --out $W/slide-her > $W/slide-her.log 2>&1; echo "slide-her rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
(CUDA_VISIBLE_DEVICES=1 timeout -k 10 $1 $H --methods splid,gcsl,pchid,her-baselines,es,no-select --side-by-side --out $W/slide-rest > $W/slide-rest.log 2>&1; echo "slide-rest rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
wait
find $W -name checkpoints -type d -prune -exec rm -rf {} +
cd /tmp && find wd4 -type f -size -8M | tar czf $OUT/d4.tgz -T -
cat $W/times.txt; for f in $W/*.log $W/*/logs/*.log; do echo "== $f"; tail -n 2 $f; done
