# profile: Push control step kernels at 16/80 envs (today's default), HER per-stage table
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
export PYTHONPATH=/tmp/site:$PWD PYTHONUNBUFFERED=1
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; git log -1 --format=%h; } > $OUT/device.txt
s=$(date +%s)
timeout 200 python experiments/kernel_profile.py --task push --batch 16 80 --top 40 --out $OUT/prof.json > $OUT/prof.log 2>&1; echo "prof rc=$? $(( $(date +%s)-s )) s" >> $OUT/device.txt
s=$(date +%s)
timeout 240 python experiments/stage_budget.py --env push --algos her --out $OUT/stage-her.json > $OUT/stage.log 2>&1; echo "stage rc=$? $(( $(date +%s)-s )) s" >> $OUT/device.txt
tail -5 $OUT/device.txt
