python -m splid_jax.sweep --env push --seed 0 --seeds 5 --iterations 800 --buffer-size 200000 --checkpoint-every 0 --run-dir /tmp/bg/long --quiet --compile-cache= --no-plot
