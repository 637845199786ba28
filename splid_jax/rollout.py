"""``python -m splid_jax.rollout RUN_DIR``: load a run's newest checkpoint, roll its deterministic
policy out, report success, and draw the episodes (paths on the task's map; rendered frames of the
MuJoCo tasks where offscreen rendering is available)."""

from __future__ import annotations

import argparse
import json
import os
import sys

import jax
import jax.numpy as jnp
import numpy as np

from envs.base import InvalidConfig, step_batch
from splid_jax import checkpoint
from splid_jax.cli import add_compile_cache_flag, use_compile_cache
from splid_jax.config import TrainConfig, saved_fields
from splid_jax.train import env_settings, make_env
from splid_jax.trainer import Trainer


def load_policy(run_dir: str):
    """The task, the trainer and the newest trained state of ``run_dir``."""
    path = os.path.join(run_dir, "config.json")
    if not os.path.isfile(path):
        raise InvalidConfig("run_dir", run_dir, "a run directory holding config.json")
    with open(path) as fh:
        cfg = TrainConfig(**{**saved_fields(json.load(fh)), "run_dir": run_dir})
    env = make_env(cfg.env, **cfg.env_overrides())
    trainer = Trainer(env, cfg)
    step, state, meta = checkpoint.restore(run_dir, trainer.init(jax.random.PRNGKey(0)))
    saved = meta.get("env")  # absent from checkpoints saved before tasks recorded their options
    now = env_settings(env)
    changed = [k for k in now if saved is not None and saved.get(k) != now[k]]
    if changed:  # the policy is still worth a look under the changed task, so say it rather than stop
        what = ", ".join(f"{k}={saved.get(k)!r} then, {now[k]!r} now" for k in changed)
        print(f"note: {run_dir} was trained on another version of the task ({what})", file=sys.stderr)
    return env, trainer, state, step


def rollout(env, trainer, pstate, key, episodes: int):
    """Episodes of the deterministic policy: the states [T + 1, E] and per-step success [T, E]."""

    def one_step(s, _):
        nxt = step_batch(env, s, trainer.policy.act(pstate, s.obs, s.desired_goal))
        return nxt, nxt

    start = jax.vmap(env.reset)(jax.random.split(key, episodes))
    _, later = jax.lax.scan(one_step, start, None, length=env.episode_length)
    states = jax.tree_util.tree_map(lambda a, b: jnp.concatenate([a[None], b]), start, later)
    return states


def draw_paths(env, states, out: str, title: str) -> None:
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    ag = np.asarray(states.achieved_goal)  # [T + 1, E, G]
    goal = np.asarray(states.desired_goal[0])
    succ = np.asarray(states.success[1:]).any(axis=0)
    fig = Figure(figsize=(6, 6))
    ax = fig.add_subplot()
    if hasattr(env, "boxes"):  # the point task: draw its walls
        for x0, x1, y0, y1 in np.asarray(env.boxes):
            ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, color="0.5"))
        ax.set_xlim(-5, 5)
        ax.set_ylim(-5, 5)
    for e in range(ag.shape[1]):
        colour = "tab:green" if succ[e] else "tab:red"
        ax.plot(ag[:, e, 0], ag[:, e, 1], "-", color=colour, lw=1.2)
        ax.plot(ag[0, e, 0], ag[0, e, 1], "o", color=colour, ms=4)
        ax.plot(goal[e, 0], goal[e, 1], "*", color="k", ms=9)
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.set_xlabel("x of the achieved goal")
    ax.set_ylabel("y")
    fig.savefig(out, dpi=110, bbox_inches="tight")


def render_frames(env, states, out: str, episode: int = 0, frames: int = 6) -> bool:
    """An image strip of one episode through MuJoCo's offscreen renderer; False where no GL."""
    if not hasattr(env, "mj_model"):
        return False
    try:
        import mujoco

        model = env.mj_model()
        data = mujoco.MjData(model)
        renderer = mujoco.Renderer(model, 240, 320)
    except Exception:  # no OpenGL context on this machine
        return False
    from matplotlib.figure import Figure

    qpos = np.asarray(states.physics.qpos[:, episode])
    picks = np.linspace(0, qpos.shape[0] - 1, frames).astype(int)
    fig = Figure(figsize=(3 * frames, 2.6))
    for i, t in enumerate(picks):
        data.qpos[:] = qpos[t]
        mujoco.mj_forward(model, data)
        renderer.update_scene(data)
        ax = fig.add_subplot(1, frames, i + 1)
        ax.imshow(renderer.render())
        ax.set_title(f"step {t}")
        ax.axis("off")
    fig.savefig(out, dpi=100, bbox_inches="tight")
    return True


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m splid_jax.rollout", description=__doc__.split("\n\n")[0])
    p.add_argument("run_dir")
    p.add_argument("--episodes", type=int, default=16, help="episodes to roll out (default: 16)")
    p.add_argument("--seed", type=int, default=123, help="seed of the episodes' starts and goals")
    p.add_argument("--out", default=None, help="figure of the paths (default: RUN_DIR/rollout.png)")
    add_compile_cache_flag(p)
    a = p.parse_args(argv)
    use_compile_cache(a.compile_cache)
    try:
        if a.episodes < 1:
            raise InvalidConfig("episodes", a.episodes, "an integer >= 1")
        env, trainer, state, step = load_policy(a.run_dir)
    except (InvalidConfig, checkpoint.CheckpointError) as err:
        print(f"{p.prog}: error: {err}", file=sys.stderr)
        return 2
    states = jax.jit(lambda ps, k: rollout(env, trainer, ps, k, a.episodes))(state.policy, jax.random.PRNGKey(a.seed))
    succ = np.asarray(states.success[1:] & ~states.invalid[1:])
    print(
        f"{a.run_dir} (iteration {step}): success {succ.any(axis=0).mean():.3f} at any step, "
        f"{succ[-1].mean():.3f} at the final step, over {a.episodes} episodes"
    )
    out = a.out or os.path.join(a.run_dir, "rollout.png")
    draw_paths(env, states, out, f"{trainer.cfg.env}: iteration {step}")
    print(f"paths: {out}")
    strip = os.path.splitext(out)[0] + "-frames.png"
    if render_frames(env, states, strip):
        print(f"frames: {strip}")
    elif hasattr(env, "mj_model"):
        print("frames: offscreen rendering is not available here (set MUJOCO_GL=egl on a GPU machine)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
