export CUDA_VISIBLE_DEVICES=3
t() { echo "$1 start $(date +%s)" >> /tmp/w/times.txt; shift; "$@"; echo "rc=$? end $(date +%s)" >> /tmp/w/times.txt; }
t bf16 python3 -m splid_jax.sweep --algo her --env push --seeds 5 --seed 7100 --checkpoint-every 0 --compile-cache= --no-plot --iterations 2500 --her-compute-dtype bfloat16 --run-dir /tmp/w/her_bf16 > /tmp/w/her_bf16.log 2>&1
t base python3 -m splid_jax.sweep --algo her --env push --seeds 5 --seed 7100 --checkpoint-every 0 --compile-cache= --no-plot --preset paper --iterations 1250 --run-dir /tmp/w/her_base > /tmp/w/her_base.log 2>&1
t f32 python3 -m splid_jax.sweep --algo her --env push --seeds 5 --seed 7100 --checkpoint-every 0 --compile-cache= --no-plot --iterations 100 --run-dir /tmp/w/her_f32 > /tmp/w/her_f32.log 2>&1
t bf16short python3 -m splid_jax.sweep --algo her --env push --seeds 5 --seed 7100 --checkpoint-every 0 --compile-cache= --no-plot --iterations 100 --her-compute-dtype bfloat16 --run-dir /tmp/w/her_bf16s > /tmp/w/her_bf16s.log 2>&1
