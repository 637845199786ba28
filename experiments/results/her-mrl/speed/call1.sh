# Call 1 (4 GPUs): Figure 3 on Push at 20,000 episodes (paper presets), side by side, 1 GPU (GPU 2) against 2
# (GPUs 0,1) at once; HER at mrl's settings in bfloat16 on GPU 3 (1M steps, fresh seeds 7100-7104), then HER at
# Baselines' (paper preset, same seeds, 1M steps) and a float32 peer of 100 iterations. Runs go on in the background.
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1 PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/w; mkdir -p $W
nvidia-smi -L > $W/gpus.txt; nvidia-smi topo -m >> $W/gpus.txt
nvidia-cuda-mps-control -d && echo "mps started $(date +%s)" > $W/mps.txt
sleep 1
S="python3 -m splid_jax.sweep --algo her --env push --seeds 5 --seed 7100 --checkpoint-every 0 --compile-cache= --no-plot"
cat > $W/her.sh <<EOS
export CUDA_VISIBLE_DEVICES=3
t() { echo "\$1 start \$(date +%s)" >> $W/times.txt; shift; "\$@"; echo "rc=\$? end \$(date +%s)" >> $W/times.txt; }
t bf16 $S --iterations 2500 --her-compute-dtype bfloat16 --run-dir $W/her_bf16 > $W/her_bf16.log 2>&1
t base $S --preset paper --iterations 1250 --run-dir $W/her_base > $W/her_base.log 2>&1
t f32 $S --iterations 100 --run-dir $W/her_f32 > $W/her_f32.log 2>&1
t bf16short $S --iterations 100 --her-compute-dtype bfloat16 --run-dir $W/her_bf16s > $W/her_bf16s.log 2>&1
EOS
setsid nohup bash $W/her.sh > $W/her_sh.log 2>&1 < /dev/null &
setsid nohup python3 experiments/multi_gpu.py $W/mg --gpus 2 --concurrent --parts figure --figure-episodes 20000 \
  --figure-args "--set preset=paper" --figure-out $W/figs --budget-s 1150 > $W/mg.log 2>&1 < /dev/null &
sleep ${WAIT:-555}
cd /tmp && tar czf $OUT/snap1.tgz --exclude='*.ckpt' --exclude='checkpoints' w 2>/dev/null
tail -n 4 $W/her_bf16.log $W/mg.log; cat $W/times.txt; nvidia-smi --query-gpu=index,utilization.gpu,memory.used --format=csv
