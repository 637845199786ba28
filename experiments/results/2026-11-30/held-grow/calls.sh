# call 1 (BUDGET=560), first attempt: from the repository root, python -m ran main's code, so the six growing arms
# stopped at their first flag; its default (hs0) and --held-share 0.2 (hs0.2) arms ran in full and are in runs.tar.xz.
# call 2 (BUDGET=560): the script below, the growing arms on the tuning seeds, then the rule's choice on fresh seeds.
# x2 host under MPS, with the growing held share's code (not kept; NOTES) copied to .gpu/ramp. Part 1, tuning seeds
# 1000-1004: eight growing held shares on Push, 80 iterations, 4 programs per GPU. Part 2, the rule fixed before the
# call: the growing arm with the highest mean final-step success over 5,000 and 10,000 episodes on the tuning seeds runs
# on 7100-7104 (GPU 0) and 9300-9304 (GPU 1), which chose nothing, with the default beside it on each GPU.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
T0=$(date +%s); END=$(( T0 + ${BUDGET:-560} ))
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=/tmp/site; cd .gpu/ramp  # python -m puts the working directory first on the path
pgrep -f nvidia-cuda-mps-control >/dev/null || nvidia-cuda-mps-control -d
W=/tmp/s11; mkdir -p $W/arms $W/fresh
S="python3 -m splid_jax.sweep --env push --seeds 5 --iterations 80 --checkpoint-every 0 --compile-cache= --no-plot"
arm() { g=$1; d=$2; n=$3; shift 3; left=$(( END - $(date +%s) - 15 ))
  CUDA_VISIBLE_DEVICES=$g timeout -s TERM -k 10 $left $S --run-dir $W/$d/$n "$@" > $W/$d/$n.log 2>&1
  echo "$d/$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
T="--seed 1000"
arm 0 arms g0.1_80 $T --held-share 0.1 --held-share-grow 80 & arm 0 arms g0.4_40 $T --held-share 0.4 --held-share-grow 40 & arm 0 arms g0.3_80 $T --held-share 0.3 --held-share-grow 80 &
arm 0 arms g0.2_80 $T --held-share 0.2 --held-share-grow 80 &
arm 1 arms g0.4_80 $T --held-share 0.4 --held-share-grow 80 & arm 1 arms g0.3_40 $T --held-share 0.3 --held-share-grow 40 &
arm 1 arms g0.2_40 $T --held-share 0.2 --held-share-grow 40 & arm 1 arms g0.6_80 $T --held-share 0.6 --held-share-grow 80 &
wait
BEST=$(python3 - "$W/arms" <<'PY'
import glob, json, sys
best = None
for d in sorted(glob.glob(sys.argv[1] + "/g*_*/")):
    finals = []
    for f in glob.glob(d + "*/metrics.jsonl"):
        rows = {r["episodes"]: r for r in map(json.loads, open(f)) if "eval_success_final" in r}
        finals += [rows[e]["eval_success_final"] for e in (5000, 10000) if e in rows]
    if len(finals) == 10:
        score = sum(finals) / 10
        print(d, round(score, 4), file=sys.stderr)
        best = max(best or (score, d), (score, d))
print(best[1].rstrip("/").rsplit("/", 1)[1] if best else "")
PY
)
echo "chosen: $BEST" | tee -a $W/times.txt
if [ -n "$BEST" ]; then
  F=${BEST#g}; SHARE=${F%_*}; GROW=${F#*_}
  G="--held-share $SHARE --held-share-grow $GROW"
  arm 0 fresh d7100 --seed 7100 & arm 0 fresh ${BEST}_7100 --seed 7100 $G &
  arm 1 fresh d9300 --seed 9300 & arm 1 fresh ${BEST}_9300 --seed 9300 $G &
  wait
fi
cd $W && find arms fresh -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -not -path '*/checkpoints/*' \
  -size -4M | tar czf $OUT/runs.tgz -T - times.txt
nvidia-smi -L; cat $W/times.txt; for f in $W/*/*.log; do echo "== $f"; grep -v '^\s*$' $f | tail -n 1; done
