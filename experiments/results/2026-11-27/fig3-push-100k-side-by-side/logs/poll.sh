# Poll the side-by-side figure for up to $1 seconds (until its parent has ended), then report and pack its records.
set -u
limit=${1:-540}
end=$(( $(date +%s) + limit ))
while [ ! -f /tmp/meta/parent.rc ] && [ $(date +%s) -lt $end ]; do sleep 5; done
now=$(date -u +%s); start=$(cat /tmp/meta/start.txt)
echo "elapsed since launch: $(( now - start )) s; parent rc: $(cat /tmp/meta/parent.rc 2>/dev/null || echo running)" | tee -a /tmp/meta/polls.txt
tail -3 /tmp/meta/parent.log | cut -c1-400 | tee -a /tmp/meta/polls.txt
for f in /tmp/fig/logs/*.log; do echo "== $f"; tail -2 $f | cut -c1-250; done
nvidia-smi --query-gpu=utilization.gpu,memory.used --format=csv,noheader | tee -a /tmp/meta/polls.txt
cd /tmp && find fig meta -type f -not -path "*checkpoint*" \( -name "*.json" -o -name "*.jsonl" -o -name "*.log" -o -name "*.rc" -o -name "*.txt" -o -name "*.csv" -o -name "*.png" -o -name "*.cmd" \) | tar czf $OUT/fig.tgz -T -
