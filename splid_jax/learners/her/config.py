"""HER's own settings. The defaults are the strongest public DDPG+HER, spitis/mrl's
``best_slide_config`` (``mrl/configs/continuous_off_policy.py``); ``BASELINES`` holds the OpenAI Baselines
settings (``baselines/her/experiment/config.py``) that the SPLID paper's Figure 3 compares against."""

from __future__ import annotations

import dataclasses

from splid_jax.common.errors import check
from splid_jax.common.fields import field


@dataclasses.dataclass(frozen=True)
class HerConfig:
    """HER's own settings. Normalised inputs are clipped to +-``networks.CLIP_NORMALISED`` (5, Baselines'
    norm_clip). A sampled goal is the transition's own with weight 1, a later achieved goal of its episode
    with weight ``replay_k`` and a stored episode's desired goal with weight ``actual_k``."""

    replay_k: int = field(2, "relabelled goals per real one drawn from later achieved goals of the same episode")
    actual_k: int = field(
        2,
        "relabelled goals per real one drawn from the desired goals of any stored episode (mrl's 'actual'; "
        "futureactual_2_2 is replay_k=2, actual_k=2; Baselines' future_4 is replay_k=4, actual_k=0)",
    )
    actual_warm_up: int = field(
        25_000,
        "with actual_k > 0, stored transitions before 'actual' and real goals are drawn: until then every goal is a "
        "future one (mrl's future_warm_up)",
    )
    gamma: float = field(0.98, "discount; 0.98 for the 50-step episodes (Baselines: 1 - 1/T)")
    hidden: tuple[int, ...] = field((512, 512, 512), "hidden layer widths of the actor and of the critic (ReLU)")
    layer_norm: bool = field(True, "LayerNorm after each hidden layer of the actor and the critic")
    actor_lr: float = field(1e-3, "Adam learning rate of the actor")
    critic_lr: float = field(1e-3, "Adam learning rate of the critic")
    batch_size: int = field(2000, "transitions per gradient step")
    buffer_transitions: int = field(2_500_000, "replay capacity in transitions, stored as whole episodes (FIFO)")
    update_every: int = field(
        2,
        "one gradient step per this many collected transitions, every env counted (mrl's optimize_every); "
        "0: n_batches steps per iteration",
    )
    n_batches: int = field(40, "gradient steps per iteration when update_every=0 (Baselines' n_batches per cycle)")
    target_every: int = field(
        10, "the target networks move every this many gradient steps; 0: once per iteration, after its steps"
    )
    polyak: float = field(0.95, "target = polyak * target + (1 - polyak) * online, at each target update")
    action_l2: float = field(0.01, "weight of the actor's mean squared action penalty")
    random_eps: float = field(0.2, "exploration: probability of a uniformly random action")
    noise_eps: float = field(0.1, "exploration: std of the Gaussian noise added to the actor's action")
    random_transitions: int = field(10_000, "the first this many collected transitions take uniformly random actions")
    warm_up: int = field(5_000, "no gradient step until the buffer holds this many transitions")
    matmul_precision: str = field(
        "default",
        "precision of the gradient steps' float32 matrix products on a GPU: default (JAX's: TensorFloat-32 on "
        "NVIDIA GPUs since Ampere), float32, tensorfloat32 or bfloat16 (jax.default_matmul_precision)",
    )
    compute_dtype: str = field(
        "float32",
        "dtype of the actor's and critic's hidden layers: float32, or bfloat16 for mixed precision on a GPU's "
        "tensor cores (parameters, optimiser, normaliser, output layers and TD targets stay float32)",
    )
    norm_eps: float = field(0.01, "std floor of the observation and goal normaliser")
    clip_obs: float = field(200.0, "observations and goals are clipped to +-clip_obs before normalising")

    def __post_init__(self):
        object.__setattr__(self, "hidden", tuple(int(w) for w in self.hidden))
        for name in ("replay_k", "actual_k", "actual_warm_up", "update_every", "n_batches", "target_every"):
            check(getattr(self, name) >= 0, f"her.{name}", getattr(self, name), "an integer >= 0")
        check(self.update_every or self.n_batches >= 1, "her.n_batches", self.n_batches, ">= 1 when her.update_every=0")
        for name in ("random_transitions", "warm_up"):
            check(getattr(self, name) >= 0, f"her.{name}", getattr(self, name), "an integer >= 0")
        precisions = ("default", "float32", "tensorfloat32", "bfloat16")
        check(
            self.matmul_precision in precisions, "her.matmul_precision", self.matmul_precision, " or ".join(precisions)
        )
        dtypes = ("float32", "bfloat16")
        check(self.compute_dtype in dtypes, "her.compute_dtype", self.compute_dtype, " or ".join(dtypes))
        check(0 <= self.gamma < 1, "her.gamma", self.gamma, "in [0, 1)")
        check(len(self.hidden) >= 1 and min(self.hidden) >= 1, "her.hidden", self.hidden, "one or more widths >= 1")
        check(self.actor_lr > 0, "her.actor_lr", self.actor_lr, "> 0")
        check(self.critic_lr > 0, "her.critic_lr", self.critic_lr, "> 0")
        check(self.batch_size >= 1, "her.batch_size", self.batch_size, "an integer >= 1")
        check(self.buffer_transitions >= 1, "her.buffer_transitions", self.buffer_transitions, "an integer >= 1")
        check(0 <= self.polyak <= 1, "her.polyak", self.polyak, "in [0, 1]")
        check(self.action_l2 >= 0, "her.action_l2", self.action_l2, ">= 0")
        check(0 <= self.random_eps <= 1, "her.random_eps", self.random_eps, "in [0, 1]")
        check(self.noise_eps >= 0, "her.noise_eps", self.noise_eps, ">= 0")
        check(self.norm_eps > 0, "her.norm_eps", self.norm_eps, "> 0")
        check(self.clip_obs > 0, "her.clip_obs", self.clip_obs, "> 0")

    @property
    def future_p(self) -> float:
        """The share of a batch relabelled with a later achieved goal of the same episode."""
        return self.replay_k / (1.0 + self.replay_k + self.actual_k)

    @property
    def actual_p(self) -> float:
        """The share of a batch relabelled with a stored episode's desired goal."""
        return self.actual_k / (1.0 + self.replay_k + self.actual_k)

    def updates_per_iteration(self, transitions: int) -> int:
        """Gradient steps after an iteration that collected ``transitions``."""
        return transitions // self.update_every if self.update_every else self.n_batches


# OpenAI Baselines' DDPG+HER, the HER of the SPLID paper's Figure 3: its curves ran 8 MPI workers of 2 episodes
# each per cycle (16 episodes, the run's num_envs) whose batches of 256 average to one step of 2048.
BASELINES = dict(
    replay_k=4,
    actual_k=0,
    actual_warm_up=0,
    hidden=(256, 256, 256),
    layer_norm=False,
    batch_size=2048,
    buffer_transitions=1_000_000,
    update_every=0,
    n_batches=40,
    target_every=0,
    action_l2=1.0,
    random_eps=0.3,
    noise_eps=0.2,
    random_transitions=0,
    warm_up=0,
)
BASELINES_WORKERS = 8
# What a run's HER options are read against (its her_defaults): HerConfig's own, or Baselines' for runs recorded
# while those were HER's defaults.
DEFAULTS = {"mrl": {}, "baselines": BASELINES}


# settings that change how fast the gradient steps run, not what they compute
_SPEED_ONLY = ("matmul_precision", "compute_dtype")


def settings_name(her: HerConfig) -> str | None:
    """Whose DDPG+HER ``her`` is, as figures name it: "mrl" or "Baselines" (whatever the precision of its
    products), else None."""
    plain = dataclasses.replace(her, **{name: getattr(HerConfig(), name) for name in _SPEED_ONLY})
    for name, settings in (("mrl", {}), ("Baselines", BASELINES)):
        if plain == HerConfig(**settings):
            return name
    return None
