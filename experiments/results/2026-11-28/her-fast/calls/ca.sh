# Call A (2 GPUs): GPU 0 HER (mrl, bf16) 8 envs, Push, tuning seeds 1000-1004, 10k episodes (whole-run rate);
# GPU 1: updates/explore times + profile (8/16/32 envs), Baselines preset rate, then 16 envs to 10k episodes
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/wa; mkdir -p $W/arms; T0=$(date +%s)
nvidia-smi -L > $W/gpus.txt
S="python3 -m splid_jax.sweep --env push --algo her --seeds 5 --seed 1000 --checkpoint-every 0 --compile-cache= --no-plot"
arm() { g=$1; lim=$2; n=$3; shift 3; CUDA_VISIBLE_DEVICES=$g timeout $lim $S --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 575 mrl8 --iterations 1250 --her-compute-dtype bfloat16 &
(CUDA_VISIBLE_DEVICES=1 timeout 170 python3 experiments/results/2026-11-28/her-fast/calls/her_grad.py $W/her_grad.json > $W/her_grad.log 2>&1; echo "her_grad rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
 arm 1 100 base --iterations 300 --preset paper
 arm 1 $(( 578 - ($(date +%s) - T0) )) mrl16 --iterations 625 --num-envs 16 --her-compute-dtype bfloat16) &
wait
cd /tmp && tar czf $OUT/ca.tgz wa 2>/dev/null
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; grep -i "steps/s\|compile\|episodes" $f | tail -n 4; done; cat $W/her_grad.log | tail -5
