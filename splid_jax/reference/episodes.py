"""Episodes of a policy in each simulator, batched, from matched starts or each one's own, and their
success rates with Wilson 95 % intervals."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from splid_jax.reference.extra import make_reference
from splid_jax.reference.mapping import our_starts, reference_start, shifted

Z95 = 1.959963984540054  # the normal quantile of a two-sided 95 % interval


@dataclasses.dataclass(frozen=True)
class Episodes:
    """Batched episodes of one simulator, numpy: obs [E, T + 1, O], achieved [E, T + 1, 3],
    goal [E, 3], success [E, T] (after each step), actions [E, T, 4]."""

    obs: np.ndarray
    achieved: np.ndarray
    goal: np.ndarray
    success: np.ndarray
    actions: np.ndarray
    dt: float

    def summary(self) -> dict:
        return summarise(self.success.any(axis=1), self.success[:, -1], final_distance(self))

    def save(self, path: str) -> None:
        """Its arrays as an npz: the hand-off from a reference run in another interpreter."""
        np.savez(path, dt=self.dt, **{k: getattr(self, k) for k in ("obs", "achieved", "goal", "success", "actions")})

    @classmethod
    def load(cls, path: str) -> Episodes:
        with np.load(path) as f:
            return cls(**{k: f[k] for k in ("obs", "achieved", "goal", "success", "actions")}, dt=float(f["dt"]))


def final_distance(ep: Episodes) -> np.ndarray:
    return np.linalg.norm(ep.achieved[:, -1] - ep.goal, axis=-1)


def run_reference(task: str, act, episodes: int, seed: int, starts: dict | None = None,
                  batch: int = 50) -> Episodes:  # fmt: skip
    """``episodes`` of ``act(obs [B, O], goal [B, 3]) -> actions [B, 4]`` in the reference, ``batch``
    envs in lockstep (episodes never end early). Episode i resets with seed ``seed + i`` and, with
    ``starts`` (``our_starts``), is then put at our i-th start."""
    envs = [make_reference(task) for _ in range(min(batch, episodes))]
    steps = envs[0].spec.max_episode_steps
    out = {k: [] for k in ("obs", "achieved", "goal", "success", "actions")}
    for first in range(0, episodes, len(envs)):
        live = envs[: min(len(envs), episodes - first)]
        dicts = []
        for j, env in enumerate(live):
            o, _ = env.reset(seed=seed + first + j)
            if starts is not None:
                i = first + j
                xy = None if starts["object_xy"] is None else starts["object_xy"][i]
                o = reference_start(env, xy, starts["goal"][i])
            dicts.append(o)
        obs = [np.stack([d["observation"] for d in dicts])]
        ach = [np.stack([d["achieved_goal"] for d in dicts])]
        goal = np.stack([d["desired_goal"] for d in dicts])
        succ, acts = [], []
        for _ in range(steps):
            a = np.clip(np.asarray(act(obs[-1].astype(np.float32), goal.astype(np.float32)), np.float64), -1, 1)
            res = [env.step(a[j]) for j, env in enumerate(live)]
            obs.append(np.stack([r[0]["observation"] for r in res]))
            ach.append(np.stack([r[0]["achieved_goal"] for r in res]))
            succ.append([bool(r[4]["is_success"]) for r in res])
            acts.append(a)
        out["obs"].append(np.stack(obs, 1))
        out["achieved"].append(np.stack(ach, 1))
        out["goal"].append(goal)
        out["success"].append(np.array(succ).T)
        out["actions"].append(np.stack(acts, 1))
    u = envs[0].unwrapped
    dt = float(u.n_substeps * u.model.opt.timestep)
    for env in envs:
        env.close()
    return Episodes(**{k: np.concatenate(v) for k, v in out.items()}, dt=dt)


def run_ours(env, act, start) -> Episodes:
    """Our task's episodes from the batched ``start`` under ``act(obs, goal) -> action`` (jax)."""
    import jax
    import jax.numpy as jnp

    from envs.base import step_batch

    @jax.jit
    def go(s0):
        def one(s, _):
            a = jnp.clip(act(s.obs, s.desired_goal), -1.0, 1.0)
            nxt = step_batch(env, s, a)
            return nxt, (nxt, a)

        _, (later, acts) = jax.lax.scan(one, s0, None, length=env.episode_length)
        return later, acts

    later, acts = go(start)
    cat = lambda a, b: np.concatenate([np.asarray(a)[:, None], np.moveaxis(np.asarray(b), 0, 1)], 1)  # noqa: E731
    return Episodes(
        obs=cat(start.obs, later.obs),
        achieved=cat(start.achieved_goal, later.achieved_goal),
        goal=np.asarray(start.desired_goal),
        success=np.moveaxis(np.asarray(later.success & ~later.invalid), 0, 1),
        actions=np.moveaxis(np.asarray(acts), 0, 1),
        dt=float(env.dt),
    )


def wilson(successes: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion: unlike the normal one it stays inside [0, 1]
    and is not empty at 0 or n successes."""
    if n <= 0:
        return (0.0, 1.0)
    p = successes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    lo = 0.0 if successes == 0 else max(0.0, centre - half)
    return (lo, 1.0 if successes == n else min(1.0, centre + half))


def summarise(any_step, final_step, distance) -> dict:
    """Success at any and at the final step with Wilson 95 % intervals, and the median final distance."""
    any_step, final_step = np.asarray(any_step, bool), np.asarray(final_step, bool)
    n = int(any_step.size)
    out = {"episodes": n}
    for name, hits in (("success_any", any_step), ("success_final", final_step)):
        out[name] = float(hits.mean())
        out[name + "_ci95"] = list(wilson(int(hits.sum()), n))
    out["median_final_distance"] = float(np.median(distance))
    return out


def ours_from_starts(task_env, act_jax, episodes: int, seed: int) -> tuple[dict, Episodes]:
    """(``our_starts``'s starts drawn with ``seed``, our ``Episodes`` from them): the side of a matched pair that
    runs here, whichever interpreter runs the reference's."""
    import jax

    starts = our_starts(task_env, jax.random.PRNGKey(seed), episodes)
    return starts, run_ours(task_env, act_jax, starts["state"])


def matched_episodes(task_env, task: str, act_jax, act_np, episodes: int, seed: int):
    """(ours, reference) ``Episodes`` from the same starts and goals: our task's ``reset`` draws
    them, the reference is put there after its own reset."""
    starts, ours = ours_from_starts(task_env, act_jax, episodes, seed)
    return ours, matched_reference(task_env, task, act_np, starts, seed)


def matched_reference(task_env, task: str, act_np, starts: dict, seed: int) -> Episodes:
    """The reference's episodes from ``starts`` (``our_starts``'s, our task's coordinates; ``state`` not needed),
    moved into the reference's coordinates by the homes of its env reset with ``seed``."""
    probe = make_reference(task)
    probe.reset(seed=seed)
    there = shifted(starts, task_env, probe)
    probe.close()
    return run_reference(task, act_np, len(starts["goal"]), seed, starts=there)
