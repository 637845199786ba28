# Slide with the pads at gripper_mass=2 (the option set nearest FetchSlide-v4 on MuJoCo 3.11), fresh seeds 9000-9004:
# SPLID default on GPU 0, HER (mrl) seeds over the others; cut at the call's short budget, then exported.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/g4; mkdir -p $W/arms $W/export; T0=$(date +%s)
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
NG=$(nvidia-smi -L | wc -l); echo "gpus $NG" >> $W/times.txt
PADS=finger=pads,finger_table=1,drive=weld,gripper_mass=2
S="python3 -m splid_jax.sweep --env slide --checkpoint-every 0 --compile-cache= --no-plot --env-options $PADS"
H="$S --algo her --iterations 1250 --num-envs 16 --her-compute-dtype bfloat16"
F=--xla_gpu_enable_triton_gemm=false
STOP=${STOP:-185}
left() { echo $(( $1 - ($(date +%s) - T0) )); }
arm() {  # name gpu command...
  local n=$1 g=$2; shift 2
  CUDA_VISIBLE_DEVICES=$g timeout -k 30 $(left $STOP) "$@" --run-dir $W/arms/$n > $W/arms/$n.log 2>&1
  echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  CUDA_VISIBLE_DEVICES=$g python3 -m splid_jax.export $W/arms/$n/sigma*-s* --out $W/export/$n > $W/export/$n.log 2>&1
  echo "export $n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
}
if [ "$NG" -ge 4 ]; then
  XLA_FLAGS=$F arm her-a 0 $H --seed 9000 --seeds 2 &
  XLA_FLAGS=$F arm her-b 1 $H --seed 9002 --seeds 2 &
  XLA_FLAGS=$F arm her-c 2 $H --seed 9004 --seeds 1 &
  arm splid 3 $S --seed 9000 --seeds 5 &
else
  XLA_FLAGS=$F arm her-a 0 $H --seed 9000 --seeds 3 &
  XLA_FLAGS=$F arm her-b 1 $H --seed 9003 --seeds 2 &
  arm splid 1 $S --seed 9000 --seeds 5 &
fi
wait
rm -rf $W/arms/*/checkpoints $W/arms/*/*/checkpoints 2>/dev/null
cd /tmp
for d in g4/export/her-*/*; do tar czf $OUT/$(basename $d).tgz $d; done
find g4 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' \) -not -path 'g4/export/her-*' -size -4M | tar czf $OUT/runs.tgz -T -
tar czf $OUT/splid-export.tgz g4/export/splid
ls -la $OUT; cat $W/times.txt; for f in $W/arms/*.log $W/export/*.log; do echo "== $f"; tail -n 2 $f; done
