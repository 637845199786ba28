# Call B (2 GPUs): GPU 0 updates profile (bf16, 8 envs), the written-out LayerNorm backward, cuBLAS-only GEMMs;
# GPU 1 HER (mrl, bf16) at 32 envs, Push, tuning seeds 1000-1004, 10k episodes
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/wb; mkdir -p $W/arms; T0=$(date +%s)
S="python3 -m splid_jax.sweep --env push --algo her --seeds 5 --seed 1000 --checkpoint-every 0 --compile-cache= --no-plot"
(CUDA_VISIBLE_DEVICES=1 timeout 420 $S --run-dir $W/arms/mrl32 --iterations 313 --num-envs 32 --her-compute-dtype bfloat16 > $W/arms/mrl32.log 2>&1; echo "mrl32 rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
g() { n=$1; shift; CUDA_VISIBLE_DEVICES=0 timeout 150 env "$@" python3 experiments/results/2026-11-28/her-fast/calls/her_grad.py $W/$n.json $W/trace_$n > $W/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
g prof ENVS=8 PROFILE=1
g fastln ENVS=8,16 PROFILE=0 VARIANT=fastln
g cublas ENVS=8 PROFILE=0 XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
wait
rm -rf $W/arms/*/checkpoints $W/trace_*
cd /tmp && find wb -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' \) -size -3M | tar czf $OUT/cb.tgz -T -
cat $W/times.txt; tail -n 3 $W/arms/mrl32.log; for n in prof fastln cublas; do tail -n 3 $W/$n.log | cut -c1-600; done
