"""The settings of the behaviour-cloning learners (SPLID, GCSL, PCHID), validated on construction.

A run's ``TrainConfig`` holds them as its ``cloning`` field; its config.json and command line keep them
flat beside the run's own settings (one level), as runs have always recorded them."""

from __future__ import annotations

import dataclasses

from splid_jax.common.errors import check
from splid_jax.common.fields import field

RELABELS = ("paper", "hold", "stop", "exact")  # splid.relabel.STRATEGIES, named here without importing JAX
STANDING_STILL = ("stop",)  # whose held pairs carry the zero action (Strategy.stands_still): held_share finds them
GCSL_RELABELS = ("final", "future")
OPTIMISERS = ("adam", "rmsprop")


@dataclasses.dataclass(frozen=True)
class ImitationConfig:
    """The cloning learners' settings: flat beside the run's own on the command line and in config.json; a
    ``None`` default is the preset's (``splid_jax.presets``), which ``TrainConfig`` resolves before building
    this."""

    sigma: float = field(1.0, "std of the Gaussian exploration noise added to the policy's action")
    sigma_end: float = field(
        None,
        "exploration noise at the end of its annealing, as a fraction of sigma: the std falls linearly from "
        "sigma to sigma_end x sigma over the first sigma_anneal iterations (1: constant)",
    )
    sigma_anneal: int = field(
        None, "iterations over which sigma anneals to sigma_end x sigma, which it keeps from then on"
    )
    horizon: int = field(None, "learning horizon H: hindsight goals come from 1..H steps ahead")
    horizon_end: int = field(
        None,
        "splid: the learning horizon at the end of the noise's annealing: H falls linearly to horizon_end over "
        "the first sigma_anneal iterations, so long horizons speed early learning and short ones judge the "
        "final approach (0: H throughout; with --horizon given and this not, 0)",
        recorded_when_set=True,
        unrecorded=0,
    )
    gripper_hold: int = field(
        1,
        "pick_and_place: steps for which the exploration noise on the fingers' open/close command is held "
        "before it is drawn again (1: afresh every step, as the arm's), so a grasp met by chance lasts long "
        "enough for the arm's noise to lift the object",
        recorded_when_set=True,
    )
    explore_subgoal_reach: float = field(
        None,
        "splid, gcsl, pchid: exploration acts towards a subgoal on the line to the goal at most this far from the "
        "achieved goal (m on the Fetch tasks), as evaluations do with eval_subgoal_reach; relabelling and SELECT "
        "are unchanged. 0: the goal itself",
        recorded_when_set=True,
        unrecorded=0.0,
    )
    select: bool = field(True, "SELECT by first hit time; --no-select stores every relabelled pair (ablation)")
    relabel: str = field(
        None,
        "splid/pchid candidates: paper (Algorithm 2 exactly), hold (also steps whose goal is already "
        "achieved and held for H steps, kept when the policy is not at the goal after H steps), stop "
        "(hold, with the held pairs labelled by the zero action: stand still at a reached goal) or exact (hold, "
        "every verdict at exactly h steps: kept when the policy is not at g' after h steps, so a push that stops "
        "at g' is kept beside one that passes it sooner)",
    )
    gcsl_relabel: str = field(
        "final", "gcsl: the later goal each step is paired with: final (the episode's last) or future (uniform)"
    )
    pchid_every: int = field(
        0,
        "pchid: iterations per horizon step; the horizon is min(H, 1 + iteration // pchid_every), "
        "0 picks pchid_every so that H is reached half-way through the run",
    )
    select_lanes: float = field(
        None,
        "parallel SELECT replay lanes per T x N explored steps, up to H (speed only, never a verdict): above 1 "
        "an explored step's candidates replay side by side in fewer rounds (a GPU steps a wider batch in little "
        "more time, up to a point)",
    )
    buffer_size: int = field(None, "relabel buffer capacity (FIFO)")
    buffer_window: int = field(
        None,
        "cloning learners: behaviour cloning draws from the newest buffer_window pairs alone, as a FIFO buffer of "
        "that capacity would hold them; a traced setting, so one sweep compares buffer capacities up to "
        "buffer_size (0: the whole buffer; with buffer_size given and this not, 0)",
        recorded_when_set=True,
        unrecorded=0,
    )
    buffer_window_grow: int = field(
        None,
        "cloning learners, with buffer_window: the window grows linearly from buffer_window to the whole buffer "
        "over the first buffer_window_grow iterations, so the start clones the newest pairs and a long run keeps "
        "the learning phase's; a traced setting (0: fixed; with buffer_size or buffer_window given and this not, 0)",
        recorded_when_set=True,
        unrecorded=0,
    )
    batch_size: int = field(None, "behaviour-cloning minibatch size")
    bc_steps: int = field(None, "behaviour-cloning gradient steps per iteration (with bc_reuse: at most)")
    bc_reuse: float = field(
        None,
        "cloning learners: behaviour-cloning samples per newly stored pair, so an iteration runs ceil(bc_reuse x new "
        "pairs / batch_size) steps, at least 1 and at most bc_steps; SELECT keeps fewer pairs as the policy improves, "
        "and a fixed step count then trains ever longer on the same pairs (the authors' code: 30 samples per new "
        "pair). 0: bc_steps every iteration",
        recorded_when_set=True,
        unrecorded=0.0,
    )
    held_share: float = field(
        None,
        "cloning learners with --relabel stop: the share of each behaviour-cloning batch drawn from the held-goal "
        "pairs (those labelled with the zero action) in the cloning window; they are a few percent of the buffer, "
        "yet the only pairs that teach standing still beside an object on its goal. A traced setting (0: uniform)",
        recorded_when_set=True,
        unrecorded=0.0,
    )
    learning_rate: float = field(None, "learning rate of the behaviour-cloning step")
    optimiser: str = field(
        None, "behaviour cloning's optimiser: adam or rmsprop (PyTorch's, the authors' code's)",
        recorded_when_set=True, unrecorded="adam",
    )  # fmt: skip
    policy_ema: float = field(
        None,
        "Polyak average of the cloned parameters that acts (explore, SELECT, eval): "
        "acting = d * acting + (1 - d) * cloned after each BC step; 0 acts with the cloned ones",
    )
    hidden: tuple[int, ...] = field(
        None, "hidden layer widths of the policy MLP, e.g. 64,64,64 (her: see --her-options hidden)"
    )
    normalise: bool = field(None, "normalise policy inputs with running mean and std")
    relative_goal: bool = field(
        None, "also feed the policy the goal minus the achieved goal (read off the observation), not only both"
    )

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
        check(0 <= self.held_share < 1, "held_share", self.held_share, "in [0, 1) (0: uniform batches)")
        allowed = f"0 unless --relabel {' or '.join(STANDING_STILL)} (its held pairs are the zero-action ones)"
        check(self.held_share == 0 or self.relabel in STANDING_STILL, "held_share", self.held_share, allowed)
        check(self.learning_rate > 0, "learning_rate", self.learning_rate, "> 0")
        check(self.optimiser in OPTIMISERS, "optimiser", self.optimiser, "one of " + ", ".join(OPTIMISERS))
        check(0 <= self.policy_ema < 1, "policy_ema", self.policy_ema, "in [0, 1)")
        check(len(self.hidden) >= 1 and min(self.hidden) >= 1, "hidden", self.hidden, "one or more widths >= 1")
