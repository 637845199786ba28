# Call 2: HER (mrl) alone, on the top face's friction $TOP (arm her) beside the task's (arm her1), same seeds.
# Slide with the reference's pads, the pads' friction on the puck's top face alone lowered to $TOP (pad_top_friction;
# the side keeps 1): HER (mrl) at 16 envs, bf16, cuBLAS products, to 6,000 episodes, and SPLID's default to 15,360
# episodes, fresh seeds 9200-9202 (chose nothing), each arm's 3 seeds in one process, the two side by side under MPS
# on one GPU, each cut by its own timeout if it has not finished by then; then each seed's policy exported for the
# reference evaluation. Into $OUT: ARM-MEMBER.tgz (each seed's export), runs.tgz (metrics, configs, logs).
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/ff2; mkdir -p $W/arms $W/export; T0=$(date +%s)
NG=$(nvidia-smi -L | wc -l); echo "gpus $NG" >> $W/times.txt
TOP=${TOP:-0.2}
OPTS=finger=pads,finger_table=1,drive=weld,gripper_mass=22,pad_top_friction=$TOP
S="python3 -m splid_jax.sweep --env slide --checkpoint-every 0 --compile-cache= --no-plot --seed 9200 --seeds 3"
H="$S --algo her --iterations 375 --num-envs 16 --her-compute-dtype bfloat16"  # 375 x 16 = 6,000 episodes
P="$S --iterations 30"  # 30 x 512 = 15,360 episodes
export XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
STOP_HER=${STOP_HER:-450} STOP_SPLID=${STOP_SPLID:-450}  # then export (at most 45 s) and pack: the whole within 520 s
left() { echo $(( $1 - ($(date +%s) - T0) )); }
arm() {  # name stop command...
  local n=$1 stop=$2; shift 2
  CUDA_VISIBLE_DEVICES=0 timeout -k 20 $(left $stop) "$@" --env-options $OPTS --run-dir $W/arms/$n > $W/arms/$n.log 2>&1
  echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  CUDA_VISIBLE_DEVICES=0 timeout -k 5 40 python3 -m splid_jax.export $W/arms/$n/sigma*-s* --out $W/export/$n > $W/export/$n.log 2>&1
  echo "export $n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
}
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
arm her $STOP_HER $H &
OPTS=finger=pads,finger_table=1,drive=weld,gripper_mass=22 arm her1 $STOP_HER $H &
wait
rm -rf $W/arms/*/checkpoints $W/arms/*/*/checkpoints 2>/dev/null
cd /tmp
for d in ff2/export/*/*; do [ -d "$d" ] && tar czf $OUT/$(basename $(dirname $d))-$(basename $d).tgz $d; done  # a file per seed: 16 MiB each at most
find ff2 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' \) -not -path 'ff2/export/*/*/*' -size -4M | tar czf $OUT/runs.tgz -T -
echo "top $TOP, $(( $(date +%s) - T0 ))s" >> $W/times.txt
ls -la $OUT; cat $W/times.txt; for f in $W/arms/*.log $W/export/*.log; do echo "== $f"; tail -n 2 $f; done
