#!/usr/bin/env bash
# Build the reference environment: Gymnasium-Robotics Fetch*-v4 on MuJoCo C, plus jax (CPU)
# so the scripted controllers in envs/fetch/scripted.py import unchanged.
# Usage: experiments/parity/setup_reference.sh [VENV_DIR]   (default: experiments/parity/.venv-ref)
# gymnasium-robotics 1.4.2 fails with mujoco >= 3.12, hence the pin.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="${1:-$here/.venv-ref}"
python="${PYTHON:-python3.11}"
if [ ! -x "$venv/bin/python" ]; then
  "$python" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet \
  "gymnasium-robotics==1.4.2" "mujoco==3.11.0" "numpy<3" "jax[cpu]"
"$venv/bin/python" - <<'PY'
import gymnasium as gym
import gymnasium_robotics
import jax
import mujoco

gym.register_envs(gymnasium_robotics)
env = gym.make("FetchPush-v4")
obs, _ = env.reset(seed=0)
env.step(env.action_space.sample())
print("reference ok: gymnasium-robotics", gymnasium_robotics.__version__, "mujoco", mujoco.__version__,
      "jax", jax.__version__, "obs", obs["observation"].shape)
PY
