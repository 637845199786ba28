# Call 1 (one H200): SPLID with coloured exploration noise, tuning seeds 1000-1004, one program per task under MPS
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/w; mkdir -p $W/arms; T0=$(date +%s)
nvidia-smi -L > $W/gpus.txt
nvidia-cuda-mps-control -d && echo mps > $W/mps.txt
C="--seeds 5 --seed 1000 --checkpoint-every 0 --compile-cache= --no-plot --vary noise_colour=0,1,2"
run() { n=$1; shift; python3 -m splid_jax.sweep "$@" $C --run-dir $W/arms/$n > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
run push --env push --iterations 80 &
run pnp --env pick_and_place --iterations 60 &
run slide --env slide --iterations 30 &
while [ $(( $(date +%s) - T0 )) -lt ${WAIT:-545} ] && [ $(jobs -r | wc -l) -gt 0 ]; do sleep 5; done
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/nc1.tgz -T - times.txt gpus.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo $f; tail -n 2 $f; done

# Call 2 (one H200): SPLID's default and HER (mrl) on Push, SPLID's default on PickAndPlace, fresh seeds 9300-9304, under MPS
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/w2; mkdir -p $W/arms; T0=$(date +%s)
nvidia-smi -L > $W/gpus.txt
nvidia-cuda-mps-control -d && echo mps > $W/mps.txt
C="--seeds 5 --seed 9300 --checkpoint-every 0 --compile-cache= --no-plot"
run() { n=$1; shift; python3 -m splid_jax.sweep "$@" $C --run-dir $W/arms/$n > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
XLA_FLAGS=--xla_gpu_enable_triton_gemm=false run push_her --env push --algo her --num-envs 16 --her-compute-dtype bfloat16 --iterations 625 --eval-every 25 &
run push_splid --env push --iterations 80 &
run pnp_splid --env pick_and_place --iterations 60 &
while [ $(( $(date +%s) - T0 )) -lt ${WAIT:-550} ] && [ $(jobs -r | wc -l) -gt 0 ]; do sleep 5; done
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/cmp2.tgz -T - times.txt gpus.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo $f; tail -n 2 $f; done

# Call 3 (one H200): HER (mrl) on PickAndPlace and SPLID from its standard starts, fresh seeds 9300-9304, under MPS
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/w3; mkdir -p $W/arms; T0=$(date +%s)
nvidia-smi -L > $W/gpus.txt
nvidia-cuda-mps-control -d && echo mps > $W/mps.txt
C="--seeds 5 --seed 9300 --checkpoint-every 0 --compile-cache= --no-plot"
run() { n=$1; shift; python3 -m splid_jax.sweep "$@" $C --run-dir $W/arms/$n > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
XLA_FLAGS=--xla_gpu_enable_triton_gemm=false run pnp_her --env pick_and_place --algo her --num-envs 16 --her-compute-dtype bfloat16 --iterations 800 --eval-every 25 --checkpoint-every 0 &
run pnp_splid_standard --env pick_and_place --iterations 60 --env-options grasped_starts=0 &
while [ $(( $(date +%s) - T0 )) -lt ${WAIT:-535} ] && [ $(jobs -r | wc -l) -gt 0 ]; do sleep 5; done
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/cmp3.tgz -T - times.txt gpus.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo $f; tail -n 2 $f; done
