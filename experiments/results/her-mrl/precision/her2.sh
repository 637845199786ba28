# HER (mrl settings) on Push, 5 seeds, 100 iterations: float32 (GPU 2) against tensorfloat32 (GPU 3) gradient steps, at once.
W=/tmp/w2; mkdir -p $W
S="python3 -m splid_jax.sweep --env push --algo her --seeds 5 --seed 7000 --iterations 100 --checkpoint-every 0 --compile-cache= --no-plot"
(CUDA_VISIBLE_DEVICES=2 $S --run-dir $W/f32 > $W/her_f32.log 2>&1) &
(CUDA_VISIBLE_DEVICES=3 $S --her-options matmul_precision=tensorfloat32 --run-dir $W/tf32 > $W/her_tf32.log 2>&1) &
wait
cp $W/her_f32.log $W/her_tf32.log $OUT/
tail -n 3 $W/her_f32.log $W/her_tf32.log
