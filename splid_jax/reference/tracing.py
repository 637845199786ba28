"""Traces of both simulators from the same starts (distance to goal, object speed, grip position per
step), split by outcome, and the observation slots compared one by one."""

from __future__ import annotations

import numpy as np

from splid_jax.reference.episodes import Episodes, matched_episodes


def trace_arrays(ep: Episodes, has_object: bool) -> dict:
    """Per step (T + 1): achieved-goal-to-goal distance, object speed (m/s; 0 for Reach), grip position; and the
    actions taken (T)."""
    dist = np.linalg.norm(ep.achieved - ep.goal[:, None], axis=-1)
    grip = ep.obs[..., 0:3]
    if has_object:
        speed = np.linalg.norm(ep.obs[..., 14:17] + ep.obs[..., 20:23], axis=-1) / ep.dt
    else:
        speed = np.zeros(dist.shape)
    return {"distance": dist, "object_speed": speed, "grip": grip, "success": ep.success, "actions": ep.actions}


SLOTS = {
    25: ("grip x", "grip y", "grip z", "object x", "object y", "object z", "rel x", "rel y", "rel z",
         "finger l", "finger r", "euler a", "euler b", "euler c", "rel vel x", "rel vel y", "rel vel z",
         "ang vel x", "ang vel y", "ang vel z", "grip vel x", "grip vel y", "grip vel z", "finger vel l",
         "finger vel r"),
    10: ("grip x", "grip y", "grip z", "finger l", "finger r", "grip vel x", "grip vel y", "grip vel z",
         "finger vel l", "finger vel r"),
}  # fmt: skip


def compare_slots(ours_obs: np.ndarray, fetch_obs: np.ndarray) -> dict:
    """Per observation slot, over every step of matched episodes ([E, T + 1, O] each): mean |value| in
    each simulator, mean |difference|, and the largest difference at the start (where both should agree)."""
    mean_abs = lambda x: np.abs(x).mean(axis=(0, 1))  # noqa: E731
    cols = (mean_abs(ours_obs), mean_abs(fetch_obs), mean_abs(ours_obs - fetch_obs),
            np.abs(ours_obs[:, 0] - fetch_obs[:, 0]).max(axis=0))  # fmt: skip
    keys = ("ours", "fetch", "diff", "start_diff")
    return {
        name: {k: float(c[i]) for k, c in zip(keys, cols, strict=True)}
        for i, name in enumerate(SLOTS[ours_obs.shape[-1]])
    }


def traces(task_env, task: str, act_jax, act_np, episodes: int, seed: int) -> dict:
    """Traces of both simulators from the same starts, keys ``ours_*`` and ``fetch_*`` ([E, T + 1]
    or [E, T + 1, 3]; ``*_success`` [E, T]) and the start goals."""
    ours, ref = matched_episodes(task_env, task, act_jax, act_np, episodes, seed)
    return traces_of(ours, ref, task_env.has_object)


def traces_of(ours: Episodes, ref: Episodes, has_object: bool) -> dict:
    """``traces``'s arrays of matched episodes, however the reference's were run."""
    out = {"goal_ours": ours.goal, "goal_fetch": ref.goal, "ours_obs": ours.obs, "fetch_obs": ref.obs}
    for name, ep in (("ours", ours), ("fetch", ref)):
        for k, v in trace_arrays(ep, has_object).items():
            out[f"{name}_{k}"] = v
    return out


def split_by_final(tr: dict, sim: str) -> dict:
    """Median distance and object speed per step over the episodes that succeed at the final step and
    over those that do not (the ones that reached the goal at some step but lost it, separately)."""
    succ = tr[f"{sim}_success"]
    groups = {
        "final": succ[:, -1],
        "lost": succ.any(axis=1) & ~succ[:, -1],
        "never": ~succ.any(axis=1),
    }
    out = {}
    for name, mask in groups.items():
        out[name] = {
            "episodes": int(mask.sum()),
            "median_distance": np.median(tr[f"{sim}_distance"][mask], axis=0).tolist() if mask.any() else [],
            "median_object_speed": np.median(tr[f"{sim}_object_speed"][mask], axis=0).tolist() if mask.any() else [],
        }
    return out
