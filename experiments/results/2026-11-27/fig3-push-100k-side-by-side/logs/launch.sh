# Figure 3 on Push at 100,000 episodes, the six methods side by side (--side-by-side) on one GPU under CUDA MPS.
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
rm -rf /tmp/code && mkdir -p /tmp/code && tar --exclude=./.site --exclude=./.git --exclude=./experiments/results -cf - . | tar xf - -C /tmp/code && cd /tmp/code
python -m compileall -q /tmp/site /tmp/code > /dev/null 2>&1
export PYTHONPATH=/tmp/site:/tmp/code PYTHONUNBUFFERED=1
mkdir -p /tmp/meta
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; } > /tmp/meta/device.txt
setsid nvidia-cuda-mps-control -d && echo "mps started $(date -u +%s)" >> /tmp/meta/device.txt
cmd="python -m splid_jax.figures fig3 --env push --episodes 100000 --side-by-side --set checkpoint_every=0 --compile-cache= --out /tmp/fig"
echo "$cmd" > /tmp/meta/command.txt
date -u +%s > /tmp/meta/start.txt
setsid nohup sh -c "$cmd > /tmp/meta/parent.log 2>&1; echo \$? \$(date -u +%s) > /tmp/meta/parent.rc" > /dev/null 2>&1 < /dev/null &
sleep 20; echo "processes: $(pgrep -fc 'splid_jax.figures')" >> /tmp/meta/device.txt
bash /tmp/code/.dev/fig36_poll.sh ${1:-540}
