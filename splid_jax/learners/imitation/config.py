"""The settings of the behaviour-cloning learners (SPLID, GCSL, PCHID), validated on construction.

A run's ``TrainConfig`` records them flat beside the run's own settings (its config.json and command
line keep one level); the registry builds this dataclass from it, so a learner reads only its own."""

from __future__ import annotations

import dataclasses

from splid_jax.common.errors import check

RELABELS = ("paper", "hold", "stop")  # splid.relabel.STRATEGIES, named here without importing JAX
GCSL_RELABELS = ("final", "future")
OPTIMISERS = ("adam", "rmsprop")


@dataclasses.dataclass(frozen=True)
class ImitationConfig:
    sigma: float
    sigma_end: float
    sigma_anneal: int
    horizon: int
    horizon_end: int
    gripper_hold: int
    explore_subgoal_reach: float
    select: bool
    relabel: str
    gcsl_relabel: str
    pchid_every: int
    select_lanes: float
    buffer_size: int
    buffer_window: int
    buffer_window_grow: int
    batch_size: int
    bc_steps: int
    bc_reuse: float
    learning_rate: float
    optimiser: str
    policy_ema: float
    hidden: tuple[int, ...]
    normalise: bool
    relative_goal: bool

    def __post_init__(self):
        check(self.relabel in RELABELS, "relabel", self.relabel, "one of " + ", ".join(RELABELS))
        check(self.gcsl_relabel in GCSL_RELABELS, "gcsl_relabel", self.gcsl_relabel, "final or future")
        check(self.pchid_every >= 0, "pchid_every", self.pchid_every, "an integer >= 0")
        check(self.sigma >= 0, "sigma", self.sigma, ">= 0")
        check(0 <= self.sigma_end <= 1, "sigma_end", self.sigma_end, "in [0, 1] (a fraction of sigma)")
        check(self.sigma_anneal >= 1, "sigma_anneal", self.sigma_anneal, "an integer >= 1")
        check(self.horizon >= 1, "horizon", self.horizon, "an integer >= 1 (and < the episode length)")
        check(
            0 <= self.horizon_end <= self.horizon,
            "horizon_end",
            self.horizon_end,
            f"an integer in [0, {self.horizon}] (0: H throughout; at most H)",
        )
        reach = self.explore_subgoal_reach
        check(reach >= 0, "explore_subgoal_reach", reach, "a distance >= 0 (0: no subgoals)")
        check(self.gripper_hold >= 1, "gripper_hold", self.gripper_hold, "an integer >= 1 (1: noise drawn every step)")
        check(
            0 < self.select_lanes <= self.horizon,
            "select_lanes",
            self.select_lanes,
            f"in (0, {self.horizon}] (times the explored steps; at most the horizon, one lane per candidate)",
        )
        check(self.buffer_size >= 1, "buffer_size", self.buffer_size, "an integer >= 1")
        window = self.buffer_window
        allowed = f"in [0, {self.buffer_size}] (buffer_size; 0: the whole buffer)"
        check(0 <= window <= self.buffer_size, "buffer_window", window, allowed)
        grow = self.buffer_window_grow
        check(grow >= 0, "buffer_window_grow", grow, "an integer >= 0 (0: a fixed window)")
        allowed = "0 without buffer_window (the window is already the whole buffer)"
        check(grow == 0 or window > 0, "buffer_window_grow", grow, allowed)
        check(self.batch_size >= 1, "batch_size", self.batch_size, "an integer >= 1")
        check(self.bc_steps >= 1, "bc_steps", self.bc_steps, "an integer >= 1 (no step leaves the loss undefined)")
        check(self.bc_reuse >= 0, "bc_reuse", self.bc_reuse, ">= 0 (0: bc_steps every iteration)")
        check(self.learning_rate > 0, "learning_rate", self.learning_rate, "> 0")
        check(self.optimiser in OPTIMISERS, "optimiser", self.optimiser, "one of " + ", ".join(OPTIMISERS))
        check(0 <= self.policy_ema < 1, "policy_ema", self.policy_ema, "in [0, 1)")
        check(len(self.hidden) >= 1 and min(self.hidden) >= 1, "hidden", self.hidden, "one or more widths >= 1")
