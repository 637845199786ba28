"""Why a policy reaches the goal but does not stay, and what holds it there: seeds of one setting as
one vmapped program, learning curves on both success measures, then per-step traces of the final
policies' evaluation episodes (distance to goal, share at the goal at each step, the object's speed
at the first hit), the SELECT candidates' make-up and what the relabel buffer holds at the end.

    python experiments/final_step.py --env push --seeds 5 --iterations 80 \
        --set relabel=paper --set relabel=hold --out experiments/results/2026-11-23/final-step-push

Each ``--set`` is one arm (comma-separated TrainConfig fields, HerConfig fields as her_FIELD); arms run
one after the other with the same seeds. Writes ``ARM.json`` per arm and ``ENV-traces.png`` comparing
them; ``--replot ARM.json...`` redraws that figure from saved arms."""

from __future__ import annotations

import argparse
import json
import os
import time

import jax
import jax.numpy as jnp
import numpy as np

from envs.base import step_batch
from splid_jax.common.subgoals import steered
from splid_jax.common.values import parse_overrides, typed_fields
from splid_jax.config import TrainConfig
from splid_jax.learners.her.config import HerConfig
from splid_jax.learners.her.learner import HER
from splid_jax.learners.imitation import relabel_buffer
from splid_jax.learners.splid.select import held_pairs
from splid_jax.learners.splid.trainer import Trainer

LIFTED = 0.01  # m above where the object rests: a goal in the air, an object off the table


def share(x, where):
    """The share of ``where`` at which ``x`` holds (0 where nothing is)."""
    return jnp.sum(x & where) / jnp.maximum(jnp.sum(where), 1)


def traces(env, trainer: Trainer, pstate, key, episodes: int) -> dict:
    """Per-step distance to the goal and success of the deterministic policy, and the achieved goal's
    speed (m/s) on the step of its first hit; from the task's standard starts."""
    policy = steered(trainer.policy, env, trainer.cfg.eval_subgoal_reach)  # as the run's evaluations act
    env = env.evaluation_task()
    start = jax.vmap(env.reset)(jax.random.split(key, episodes))

    def one(state, _):
        nxt = step_batch(env, state, policy.act(pstate, state.obs, state.desired_goal))
        dist = jnp.linalg.norm(nxt.achieved_goal - nxt.desired_goal, axis=-1)
        speed = jnp.linalg.norm(nxt.achieved_goal - state.achieved_goal, axis=-1) / getattr(env, "dt", 1.0)
        return nxt, (dist, nxt.success & ~nxt.invalid, speed)

    _, (dist, succ, speed) = jax.lax.scan(one, start, None, length=env.episode_length)
    first = jnp.argmax(succ, axis=0)
    hit = jnp.any(succ, axis=0)
    speed_at_hit = jnp.where(hit, jnp.take_along_axis(speed, first[None], axis=0)[0], jnp.nan)
    stays = hit & jnp.all(jnp.where(jnp.arange(env.episode_length)[:, None] >= first[None], succ, True), axis=0)
    # goals above where the object rests (PickAndPlace's half in the air) against goals on the table
    air = start.desired_goal[:, -1] - start.achieved_goal[:, -1] > LIFTED
    if start.desired_goal.shape[-1] != 3:  # planar goals have no height
        air = jnp.zeros_like(air)
    final = succ[-1]

    return {
        "air_goal_share": jnp.mean(air),
        "hit_air": share(hit, air),
        "hit_table": share(hit, ~air),
        "final_air": share(final, air),
        "final_table": share(final, ~air),
        "success_per_step": jnp.mean(succ, axis=1),
        "distance_median_per_step": jnp.median(dist, axis=1),
        "speed_at_first_hit_median": jnp.nanmedian(speed_at_hit),
        "hit": jnp.mean(hit),
        "hit_and_stayed": jnp.mean(stays),
    }


def goal_distances(env, buf) -> tuple[jax.Array, jax.Array, jax.Array]:
    """Each relabel-buffer pair's goal distance from the object (m), whether the pair is filled, and whether
    its goal is held (already where the object is)."""
    start = env.achieved_goal_start
    dist = jnp.linalg.norm(buf.goal - buf.obs[:, start : start + env.goal_size], axis=-1)
    return dist, relabel_buffer.filled(buf), held_pairs(env, buf.obs, buf.goal)


def buffer_make_up(env, buf) -> dict:
    """What the relabel buffer holds at the end of training, for object tasks: the share of pairs whose
    goal is where the object already is (held goals), whose goal is lifted above the object's resting
    height (PickAndPlace's goals in the air), whose state has the object lifted, and how far the other
    goals lie from the object (m)."""
    if not getattr(env, "has_object", False):  # the Fetch tasks with an object, whose layout has its height
        return {}
    rest_z, start = env.layout.object_rest_z, env.achieved_goal_start
    obj = buf.obs[:, start : start + 3]
    dist, filled, held = goal_distances(env, buf)
    moved = filled & ~held
    return {
        "pairs": buf.size,
        "held_goal_share": share(held, filled),
        "lifted_goal_share": share(buf.goal[:, 2] > rest_z + LIFTED, filled),
        "lifted_state_share": share(obj[:, 2] > rest_z + LIFTED, filled),
        "moved_goal_distance_median": jnp.nanmedian(jnp.where(moved, dist, jnp.nan)),
        "moved_goal_distance_p90": jnp.nanpercentile(jnp.where(moved, dist, jnp.nan), 90),
    }


def arm_path(out: str, env_name: str, fields: dict) -> str:
    name = "-".join(f"{k}{v}" for k, v in fields.items()) or "default"
    name = "".join(c if c.isalnum() or c in "._-" else "_" for c in name)  # a file name, whatever the values
    return os.path.join(out, f"{env_name}-{name}.json")


def run_arm(
    env_name: str, seeds: int, base: dict, fields: dict, trace_episodes: int, first_seed: int = 1000, path: str = ""
) -> dict:
    """Trains the arm; with ``path``, its record so far is rewritten there after every evaluation, so
    a run stopped early still leaves its curve."""
    merged = {**base, **fields}
    her = typed_fields(HerConfig, {k[4:]: v for k, v in merged.items() if k.startswith("her_")}, "set.her")
    train = typed_fields(TrainConfig, {k: v for k, v in merged.items() if not k.startswith("her_")}, "set")
    cfg = TrainConfig(env=env_name, **train)
    env = cfg.make_env()
    trainer = HER(env, cfg, HerConfig(**her)) if cfg.algo == "her" else Trainer(env, cfg)
    keys = jnp.stack([jax.random.PRNGKey(first_seed + s) for s in range(seeds)])
    state = jax.jit(jax.vmap(trainer.init))(keys)
    hyper = jax.tree_util.tree_map(lambda x: jnp.broadcast_to(x, (seeds,)), trainer.hyper())
    chunk = jax.jit(jax.vmap(trainer.chunk))
    t0 = time.perf_counter()
    compiled = chunk.lower(state, hyper).compile()
    compile_s = time.perf_counter() - t0
    record = {
        "env": env_name,
        "fields": fields,
        "config": cfg.to_json(),
        "seeds": seeds,
        "first_seed": first_seed,
        "device": jax.devices()[0].device_kind,
        "date": time.strftime("%Y-%m-%d"),
        "compile_s": compile_s,
    }
    curve, t0 = [], time.perf_counter()
    for it in range(cfg.eval_every, cfg.iterations + 1, cfg.eval_every):
        state, m = compiled(state, hyper)
        m = jax.device_get(m)
        curve.append(
            {
                "iteration": it,
                "episodes": it * cfg.num_envs,
                "wall_s": time.perf_counter() - t0,
                **{k: np.asarray(v).tolist() for k, v in m.items() if k != "select_steps"},
            }
        )
        last = curve[-1]
        print(
            f"{fields} it {it:4d} ep {last['episodes']:6d} any {np.mean(last['eval_success']):.3f} "
            f"final {np.mean(last['eval_success_final']):.3f} wall {last['wall_s']:.1f}s",
            flush=True,
        )
        if path:
            with open(path, "w") as fh:
                json.dump({**record, "curve": curve, "traces": None}, fh)
    tr = jax.jit(jax.vmap(lambda ps, k: traces(env, trainer, ps, k, trace_episodes)))(
        state.policy, jax.random.split(jax.random.PRNGKey(7), seeds)
    )
    buffer = {}
    if hasattr(state, "buffer") and hasattr(state.buffer, "goal"):  # the cloning learners' relabel buffer
        buffer = jax.device_get(jax.vmap(lambda b: buffer_make_up(env, b))(state.buffer))
    return {
        **record,
        "curve": curve,
        "traces": {k: np.asarray(v).tolist() for k, v in jax.device_get(tr).items()},
        "buffer": {k: np.asarray(v).tolist() for k, v in buffer.items()},
    }


def parse_set(text: str) -> dict:
    """An arm's fields as written (they name its file); typed when its configs are built."""
    return parse_overrides(text, "set")


def figure(results: list[dict], out: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(15, 4))
    for i, r in enumerate(results):
        color = f"C{i}"
        cfg = r["config"]  # an arm without fields of its own is named by its base's learner and relabelling
        own = ",".join(f"{k}={v}" for k, v in r["fields"].items())
        label = own or f"{cfg.get('algo')}, relabel={cfg.get('relabel')}"
        ep = [c["episodes"] for c in r["curve"]]
        for key, style, name in (("eval_success", "-", "any step"), ("eval_success_final", "--", "final step")):
            y = np.array([c[key] for c in r["curve"]])
            mean, sem = y.mean(1), y.std(1, ddof=1) / np.sqrt(y.shape[1]) if y.shape[1] > 1 else 0 * y.mean(1)
            ax[0].plot(ep, mean, style, color=color, label=f"{label} ({name})")
            ax[0].fill_between(ep, mean - sem, mean + sem, color=color, alpha=0.2)
        if r["traces"] is None:  # an arm stopped before its traces
            continue
        steps = np.arange(1, len(r["traces"]["success_per_step"][0]) + 1)
        ax[1].plot(steps, np.mean(r["traces"]["success_per_step"], 0), color=color, label=label)
        ax[2].plot(steps, np.mean(r["traces"]["distance_median_per_step"], 0), color=color, label=label)
    ax[0].set(xlabel="exploration episodes", ylabel="eval success (mean ± s.e.)", title="learning curves")
    ax[1].set(xlabel="episode step", ylabel="share of episodes at the goal", title="final policies: at the goal")
    ax[2].set(xlabel="episode step", ylabel="median distance to goal (m)", title="final policies: distance to goal")
    for a in ax:
        a.legend(fontsize=7)
        a.grid(alpha=0.3)
    dates = "/".join(sorted({r["date"] for r in results}))
    fig.suptitle(f"{results[0]['env']}: {results[0]['seeds']} seeds, {results[0]['device']}, {dates}")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--env", default="push")
    p.add_argument("--seeds", type=int, default=5)
    p.add_argument("--first-seed", type=int, default=1000, help="seeds FIRST..FIRST+SEEDS-1 (1000: the tuning seeds)")
    p.add_argument("--iterations", type=int, default=None)
    p.add_argument("--set", action="append", default=[], help="one arm: KEY=VALUE[,KEY=VALUE]")
    p.add_argument("--base", default="", help="fields shared by every arm: KEY=VALUE[,KEY=VALUE]")
    p.add_argument("--trace-episodes", type=int, default=500)
    p.add_argument("--out", required=True)
    p.add_argument("--replot", nargs="+", metavar="JSON", help="draw OUT/ENV-traces.png from saved arms, no training")
    a = p.parse_args()
    if a.replot:
        results = []
        for path in a.replot:
            with open(path) as fh:
                results.append(json.load(fh))
        figure(results, os.path.join(a.out, f"{a.env}-traces.png"))
        return
    os.makedirs(a.out, exist_ok=True)
    base = parse_set(a.base)
    if a.iterations:
        base["iterations"] = a.iterations
    results = []
    for spec in a.set or [""]:
        fields = parse_set(spec)
        path = arm_path(a.out, a.env, fields)
        r = run_arm(a.env, a.seeds, base, fields, a.trace_episodes, a.first_seed, path)
        with open(path, "w") as fh:
            json.dump(r, fh)
        results.append(r)
        t = r["traces"]
        print(
            f"{r['fields']}: hit {np.mean(t['hit']):.3f} stayed {np.mean(t['hit_and_stayed']):.3f} "
            f"speed at first hit {np.mean(t['speed_at_first_hit_median']):.3f} m/s; goals in the air "
            f"{np.mean(t['air_goal_share']):.2f} (hit {np.mean(t['hit_air']):.3f}, "
            f"final {np.mean(t['final_air']):.3f}), "
            f"on the table hit {np.mean(t['hit_table']):.3f} final {np.mean(t['final_table']):.3f}; "
            f"compile {r['compile_s']:.1f}s",
            flush=True,
        )
        if r["buffer"]:
            made = ", ".join(f"{k} {np.mean(v):.3f}" for k, v in r["buffer"].items())
            print(f"{r['fields']}: buffer {made}", flush=True)
    figure(results, os.path.join(a.out, f"{a.env}-traces.png"))


if __name__ == "__main__":
    main()
