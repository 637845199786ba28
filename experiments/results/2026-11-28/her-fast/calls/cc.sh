# Call C (2 GPUs): GPU 0 Baselines preset rate, then HER (mrl, bf16, 16 envs, cuBLAS GEMMs) Push on fresh seeds
# 7100-7104 to 10k episodes; GPU 1 the same HER on PickAndPlace, fresh seeds 7000-7004, to 15,200 episodes
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/wc; mkdir -p $W/arms; T0=$(date +%s)
S="python3 -m splid_jax.sweep --algo her --seeds 5 --checkpoint-every 0 --compile-cache= --no-plot"
F=--xla_gpu_enable_triton_gemm=false
left() { echo $(( 555 - ($(date +%s) - T0) )); }
(CUDA_VISIBLE_DEVICES=1 XLA_FLAGS=$F timeout $(left) $S --env pick_and_place --seed 7000 --run-dir $W/arms/pnp16 --iterations 950 --num-envs 16 --her-compute-dtype bfloat16 > $W/arms/pnp16.log 2>&1; echo "pnp16 rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
(CUDA_VISIBLE_DEVICES=0 timeout 100 $S --env push --seed 7100 --run-dir $W/arms/base --iterations 300 --preset paper > $W/arms/base.log 2>&1; echo "base rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
 CUDA_VISIBLE_DEVICES=0 XLA_FLAGS=$F timeout $(left) $S --env push --seed 7100 --run-dir $W/arms/push16 --iterations 625 --num-envs 16 --her-compute-dtype bfloat16 > $W/arms/push16.log 2>&1; echo "push16 rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
wait
rm -rf $W/arms/*/checkpoints
cd /tmp && find wc -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' \) -size -3M | tar czf $OUT/cc.tgz -T -
ls -la $OUT; cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; grep -i "compil\|iter " $f | tail -n 3; done
