# Call 1 (4 GPUs): GPU 0 HER speed variants + kernel profile; GPUs 1-3 SPLID Push arms on tuning seeds 1000-1004
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/w; mkdir -p $W; T0=$(date +%s)
nvidia-smi -L > $W/gpus.txt
nvidia-cuda-mps-control -d && echo mps > $W/mps.txt
S="python3 -m splid_jax.sweep --env push --seeds 5 --seed 1000 --iterations 80 --checkpoint-every 0 --compile-cache= --no-plot"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g $S --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
mkdir -p $W/arms
(CUDA_VISIBLE_DEVICES=0 python3 .gpu/her_speed.py $W/her_speed.json $W/trace > $W/her_speed.log 2>&1; echo "her_speed rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
 arm 0 default & arm 0 ln --layer-norm & arm 0 ln512 --layer-norm --hidden 512,512,512 & arm 0 bc400 --bc-steps 400 & wait) &
arm 1 bc800 --bc-steps 800 &
arm 1 ln_bc400 --layer-norm --bc-steps 400 &
arm 1 w512 --hidden 512,512,512 &
arm 1 b2048 --batch-size 2048 &
arm 1 e63 --num-envs 63 --iterations 160 --sigma-anneal 160 --buffer-window-grow 400 &
while [ $(( $(date +%s) - T0 )) -lt ${WAIT:-560} ] && [ $(jobs -r | wc -l) -gt 0 ]; do sleep 5; done
cd /tmp && tar czf $OUT/c1.tgz --exclude='trace' w 2>/dev/null
cat $W/times.txt; tail -n 2 $W/arms/*.log | grep -v "^$"; cat $W/her_speed.log | head -8
# Call 2 (2 GPUs): SPLID Push arms on tuning seeds 1000-1004 (5 per GPU under MPS, no preallocation)
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/w2; mkdir -p $W/arms; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null
S="python3 -m splid_jax.sweep --env push --seeds 5 --seed 1000 --iterations 80 --checkpoint-every 0 --compile-cache= --no-plot"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g $S --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 ln --layer-norm &
arm 0 ln512 --layer-norm --hidden 512,512,512 &
arm 0 bc400 --bc-steps 400 &
arm 0 bc800 --bc-steps 800 &
arm 0 w512 --hidden 512,512,512 &
arm 1 ln_bc400 --layer-norm --bc-steps 400 &
arm 1 e63 --num-envs 63 --iterations 160 --sigma-anneal 160 --buffer-window-grow 400 &
arm 1 ln_lr1e3 --layer-norm --learning-rate 1e-3 &
arm 1 bc400_ema99 --bc-steps 400 --policy-ema 0.99 &
arm 1 ln512_bc400 --layer-norm --hidden 512,512,512 --bc-steps 400 &
while [ $(( $(date +%s) - T0 )) -lt ${WAIT:-540} ] && [ $(jobs -r | wc -l) -gt 0 ]; do sleep 5; done
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -2M | tar czf $OUT/arms2.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo $f; tail -n 1 $f; done
# Call 3 (2 GPUs): SPLID Push default on fresh seeds 7100-7104 (HER (mrl) bf16's seeds), PickAndPlace default on
# 7000-7004 (HER (mrl)'s), and a third round of Push arms on tuning seeds 1000-1004
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/w3; mkdir -p $W/arms; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null
C="--checkpoint-every 0 --compile-cache= --no-plot"
S="python3 -m splid_jax.sweep --env push --seeds 5 --seed 1000 --iterations 80 $C"
run() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g "$@" --run-dir $W/arms/$n > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm() { g=$1; n=$2; shift 2; run $g $n $S "$@"; }
run 0 push7100 python3 -m splid_jax.sweep --env push --seeds 5 --seed 7100 --iterations 80 $C &
run 1 pnp7000 python3 -m splid_jax.sweep --env pick_and_place --seeds 5 --seed 7000 --iterations 40 $C &
arm 0 bc100 --bc-steps 100 &
arm 0 b2048_bc100 --batch-size 2048 --bc-steps 100 &
arm 0 lr25e5 --learning-rate 2.5e-4 &
arm 0 ema95 --policy-ema 0.95 &
arm 1 b4096 --batch-size 4096 &
arm 1 sig01 --sigma-end 0.1 &
arm 1 ema99 --policy-ema 0.99 &
arm 1 win100k --buffer-window 100000 &
while [ $(( $(date +%s) - T0 )) -lt ${WAIT:-545} ] && [ $(jobs -r | wc -l) -gt 0 ]; do sleep 5; done
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -2M | tar czf $OUT/arms3.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo $f; tail -n 1 $f; done
# Call 4 (2 GPUs): GPU 0 kernel profile of HER's 200 updates (5 vmapped seeds, bf16); GPU 1 SPLID Push with
# --sigma-end 0.1 (chosen on 1000-1004) on fresh seeds 7100-7104
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/w4; mkdir -p $W/arms; T0=$(date +%s)
(CUDA_VISIBLE_DEVICES=1 python3 -m splid_jax.sweep --env push --seeds 5 --seed 7100 --iterations 80 --checkpoint-every 0 --compile-cache= --no-plot --sigma-end 0.1 --run-dir $W/arms/sig01_7100 > $W/arms/sig01_7100.log 2>&1; echo "sig01 rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
CUDA_VISIBLE_DEVICES=0 PROFILE_ONLY=1 python3 .gpu/her_speed.py $W/her_profile.json $W/trace > $W/her_profile.log 2>&1; echo "profile rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -2M | tar czf $OUT/c4.tgz -T - times.txt her_profile.json her_profile.log
cat times.txt; tail -n 1 arms/sig01_7100.log; tail -n 30 her_profile.log
# Call 1 (2 GPUs): GPU 0: the paper preset on Slide (seeds 2000-2004) and PickAndPlace (6000-6004), the tuned rows'
# seeds, under MPS. GPU 1: SPLID Push arms on tuning seeds 1000-1004, BC work per new pair (bc_reuse) x cap x rate.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/e1; mkdir -p $W/arms; T0=$(date +%s)
nvidia-smi -L > $W/gpus.txt; nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g timeout -k 10 $(( 545 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 paper-slide --env slide --preset paper --seed 2000 &
arm 0 paper-pnp --env pick_and_place --preset paper --seed 6000 &
P="--env push --seed 1000 --iterations 80"
arm 1 reuse200 $P --vary bc_reuse=0,10,20,40 &
arm 1 reuse400 $P --bc-steps 400 --vary bc_reuse=40,80 --vary learning_rate=5e-4,2.5e-4 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/e1.tgz -T - times.txt gpus.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done
# Call 2 (2 GPUs): SPLID PickAndPlace arms on tuning seeds 1000-1004 to 15,360 episodes: envs per iteration against
# iterations (the noise's annealing scaled with them), and Push arms over the starting noise, under MPS.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/e2; mkdir -p $W/arms; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5 --seed 1000"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g timeout -k 10 $(( 540 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
P="--env pick_and_place"
arm 0 pnp512 $P --iterations 30 &
arm 0 pnp256 $P --num-envs 256 --iterations 60 --sigma-anneal 100 &
arm 0 push-sigmas --env push --iterations 80 --sigmas 0.5,0.7 &
arm 1 pnp128 $P --num-envs 128 --iterations 120 --sigma-anneal 200 &
arm 1 pnp128_bc100 $P --num-envs 128 --iterations 120 --sigma-anneal 200 --bc-steps 100 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/e2.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done
# Call 3 (2 GPUs): PickAndPlace on fresh seeds 7000-7004 (HER (mrl)'s) and 0-4 (Figure 3's): 256 envs x 60 iterations and
# 128 x 120 (100 BC steps) beside the default's 512 x 30, to 15,360 episodes, under MPS.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/e3; mkdir -p $W/arms; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5 "
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g timeout -k 10 $(( 540 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
P="--env pick_and_place"
P="--env pick_and_place"
arm 0 pnp256_7000 $P --seed 7000 --num-envs 256 --iterations 60 --sigma-anneal 100 &
arm 0 pnp256_0 $P --seed 0 --num-envs 256 --iterations 60 --sigma-anneal 100 &
arm 1 pnp128bc100_7000 $P --seed 7000 --num-envs 128 --iterations 120 --sigma-anneal 200 --bc-steps 100 &
arm 1 pnp512_7000 $P --seed 7000 --iterations 30 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/e3.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done
# Call 4 (2 GPUs): Slide arms on tuning seeds 1000-1004 to 15,360 episodes: envs per iteration against iterations.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/e4; mkdir -p $W/arms; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5 --seed 1000"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g timeout -k 10 $(( 380 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
P="--env slide"
arm 0 slide512 $P --iterations 30 &
arm 0 slide256 $P --num-envs 256 --iterations 60 --sigma-anneal 100 &
arm 1 slide128 $P --num-envs 128 --iterations 120 --sigma-anneal 200 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/e4.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done
# Call f1 (2 GPUs, MPS): Push --sigmas 0.7,1 on fresh seeds 7100-7104 and 0-4; PickAndPlace 512 envs x 400 BC steps on tuning seeds 1000-1004; PickAndPlace default on 7000-7004 to 20,480 episodes
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/f1; mkdir -p $W/arms; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g timeout -k 10 $(( 540 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 push-sigma-7100 --env push --seed 7100 --iterations 80 --sigmas 0.7,1 &
arm 0 pnp512bc400 --env pick_and_place --seed 1000 --num-envs 512 --iterations 30 --sigma-anneal 50 --bc-steps 400 &
arm 1 pnp-default-7000 --env pick_and_place --seed 7000 &
arm 1 push-sigma-0 --env push --seed 0 --iterations 80 --sigmas 0.7,1 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/f1.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done
# Call f2 (2 GPUs)
# Tuning seeds 1000-1004: Push with the horizon starting at 12/16/20 (falling to 8) in one program; PickAndPlace's
# default (256 x 60) with 300 BC steps, and with the noise ending at 0.25 beside 0.5 in one program.
W=/tmp/f2; mkdir -p $W/arms; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5 --seed 1000"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g timeout -k 10 $(( 560 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 push-h --env push --iterations 80 --horizons 12,16,20 --horizon-end 8 &
arm 0 pnp-bc300 --env pick_and_place --iterations 60 --bc-steps 300 &
arm 1 pnp-se --env pick_and_place --iterations 60 --vary sigma_end=0.25,0.5 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/f2.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done
# Call f3 (2 GPUs)
# PickAndPlace, 256 x 60: 300 BC steps with the noise ending at 0.25 or at 0.5 (one program per seed set), on the
# tuning seeds 1000-1004 (choose) and on fresh seeds 7000-7004 (report; HER (mrl)'s).
W=/tmp/f3; mkdir -p $W/arms; T0=$(date +%s)
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5 --env pick_and_place --iterations 60 --bc-steps 300 --vary sigma_end=0.25,0.5"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g timeout -k 10 $(( 560 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 pnp-bc300-se-1000 --seed 1000 &
arm 1 pnp-bc300-se-7000 --seed 7000 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/f3.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done
# Call f4 (2 GPUs)
# PickAndPlace's candidate default (256 x 80, 300 BC steps, noise ending at 0.25; chosen on 1000-1004 in calls f2, f3)
# to 20,480 episodes on fresh seeds 7000-7004 and 0-4 (report).
W=/tmp/f4; mkdir -p $W/arms; T0=$(date +%s)
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5 --env pick_and_place --iterations 80 --bc-steps 300 --sigma-end 0.25"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g timeout -k 10 $(( 560 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 pnp-cand-7000 --seed 7000 &
arm 1 pnp-cand-0 --seed 0 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/f4.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done

# ---- call g2 (4 H200s) ----
# The cloning rate falling with the noise (--learning-rate-end, linear over sigma_anneal iterations): Push on the
# tuning seeds 1000-1004 and fresh 7100-7104 (1, 0.3, 0.1 in one program each), PickAndPlace on tuning 1000-1004 and
# fresh 7000-7004 (1, 0.2); one program per GPU. The choice is made on the tuning seeds alone.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/g2; mkdir -p $W/arms; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
NG=$(nvidia-smi -L | wc -l); echo "gpus $NG" >> $W/times.txt
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5 --iterations 80"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$(( g % NG )) timeout -k 10 $(( 545 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 push-lr-1000 --env push --seed 1000 --vary learning_rate_end=1,0.3,0.1 &
arm 1 push-lr-7100 --env push --seed 7100 --vary learning_rate_end=1,0.3,0.1 &
arm 2 pnp-lr-1000 --env pick_and_place --seed 1000 --vary learning_rate_end=1,0.2 &
arm 3 pnp-lr-7000 --env pick_and_place --seed 7000 --vary learning_rate_end=1,0.2 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/g2.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done

# ---- call g3 (4 H200s) ----
# Hindsight goals that reach the episode's desired goal cloned as that goal (--relabel stop-desired on Push,
# hold-desired on PickAndPlace; a temporary relabelling), each beside the default in the same call under MPS:
# tuning seeds 1000-1004 and fresh 7100-7104 (Push), 7000-7004 (PickAndPlace). The choice is made on the tuning seeds.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/g3; mkdir -p $W/arms; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
NG=$(nvidia-smi -L | wc -l); echo "gpus $NG" >> $W/times.txt
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5 --iterations 80"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$(( g % NG )) timeout -k 10 $(( 545 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 push-default-1000 --env push --seed 1000 &
arm 0 push-desired-1000 --env push --seed 1000 --relabel stop-desired &
arm 1 push-default-7100 --env push --seed 7100 &
arm 1 push-desired-7100 --env push --seed 7100 --relabel stop-desired &
arm 2 pnp-default-1000 --env pick_and_place --seed 1000 &
arm 2 pnp-desired-1000 --env pick_and_place --seed 1000 --relabel hold-desired &
arm 3 pnp-default-7000 --env pick_and_place --seed 7000 &
arm 3 pnp-desired-7000 --env pick_and_place --seed 7000 --relabel hold-desired &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/g3.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 1 $f; done

# ---- Call h1 (4 H200s, 2026-11-28): every SELECT verdict at the final step (temporary relabel stop-exact / hold-exact),
# beside the default; GPU 3: Figure 3's paper-preset SPLID process alone on a GPU. 421.9 s of command time.
# Every SELECT verdict at the final step (--relabel stop-exact on Push, hold-exact on PickAndPlace; temporary),
# each beside the default in the same call under MPS: tuning seeds 1000-1004, fresh 7100-7104 (Push), 7000-7004 (PnP).
# GPU 3: Figure 3's SPLID process (paper preset, 20,000 episodes) alone on a GPU, for the side-by-side figure's bound.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/h1; mkdir -p $W/arms; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
NG=$(nvidia-smi -L | wc -l); echo "gpus $NG" >> $W/times.txt
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$(( g % NG )) timeout -k 10 $(( 560 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 push-default-1000 --env push --seed 1000 --iterations 80 &
arm 0 push-exact-1000 --env push --seed 1000 --iterations 80 --relabel stop-exact &
arm 0 push-default-7100 --env push --seed 7100 --iterations 80 &
arm 0 push-exact-7100 --env push --seed 7100 --iterations 80 --relabel stop-exact &
arm 1 pnp-default-1000 --env pick_and_place --seed 1000 --iterations 80 &
arm 1 pnp-exact-1000 --env pick_and_place --seed 1000 --iterations 80 --relabel hold-exact &
arm 2 pnp-default-7000 --env pick_and_place --seed 7000 --iterations 80 &
arm 2 pnp-exact-7000 --env pick_and_place --seed 7000 --iterations 80 --relabel hold-exact &
arm 3 fig3-splid-alone --env push --preset paper --seed 0 --iterations 400 --num-envs 50 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/h1.tgz -T - times.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done
