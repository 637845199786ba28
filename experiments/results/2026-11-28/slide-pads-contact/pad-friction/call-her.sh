# Slide with the reference's pads, the pads' friction on the puck lowered to 0.2 (pad_friction) beside the task's 1,
# HER (mrl) at 16 envs, bf16, cuBLAS products, fresh seeds 9100-9102 (chose nothing), each friction's 3 seeds in one
# process, the two side by side under MPS on one GPU; cut by the call's time, then each seed's policy exported for the reference evaluation.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/h2; mkdir -p $W/arms $W/export; T0=$(date +%s)
NG=$(nvidia-smi -L | wc -l); echo "gpus $NG" >> $W/times.txt
PADS=finger=pads,finger_table=1,drive=weld,gripper_mass=22
S="python3 -m splid_jax.sweep --env slide --checkpoint-every 0 --compile-cache= --no-plot"
H="$S --algo her --iterations 1250 --num-envs 16 --her-compute-dtype bfloat16"
export XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
STOP=${STOP:-455}
left() { echo $(( $1 - ($(date +%s) - T0) )); }
arm() {  # name gpu command...
  local n=$1 g=$2; shift 2
  CUDA_VISIBLE_DEVICES=$g timeout -k 30 $(left $STOP) "$@" --run-dir $W/arms/$n > $W/arms/$n.log 2>&1
  echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  CUDA_VISIBLE_DEVICES=$g python3 -m splid_jax.export $W/arms/$n/sigma*-s* --out $W/export/$n > $W/export/$n.log 2>&1
  echo "export $n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
}
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
arm mu02 0 $H --seed 9100 --seeds 3 --env-options $PADS,pad_friction=0.2 &
arm mu1 0 $H --seed 9100 --seeds 3 --env-options $PADS &
wait
rm -rf $W/arms/*/checkpoints $W/arms/*/*/checkpoints 2>/dev/null
cd /tmp
for d in h2/export/*/*; do [ -d "$d" ] && tar czf $OUT/$(basename $(dirname $d))-$(basename $d).tgz $d; done
find h2 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' \) -not -path 'h2/export/*/*/*' -size -4M | tar czf $OUT/runs.tgz -T -
ls -la $OUT; cat $W/times.txt; for f in $W/arms/*.log $W/export/*.log; do echo "== $f"; tail -n 2 $f; done
