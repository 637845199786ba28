"""HER's own settings, with the defaults of OpenAI Baselines."""

from __future__ import annotations

import dataclasses

from splid_jax.common.errors import check
from splid_jax.common.fields import field


@dataclasses.dataclass(frozen=True)
class HerConfig:
    """HER's own settings; defaults are OpenAI Baselines' (``baselines/her/experiment/config.py``).
    Normalised inputs are clipped to +-``networks.CLIP_NORMALISED`` (5, Baselines' norm_clip)."""

    replay_k: int = field(4, "future strategy: k relabelled goals per original one (relabel probability 1 - 1/(1+k))")
    gamma: float = field(0.98, "discount; Baselines uses 1 - 1/T, 0.98 for the 50-step episodes")
    hidden: tuple[int, ...] = field((256, 256, 256), "hidden layer widths of the actor and of the critic (ReLU)")
    actor_lr: float = field(1e-3, "Adam learning rate of the actor")
    critic_lr: float = field(1e-3, "Adam learning rate of the critic")
    batch_size: int = field(
        2048,
        "transitions per gradient step: Baselines averages the gradients of 8 MPI workers' batches of 256, "
        "2048 in effect",
    )
    buffer_transitions: int = field(1_000_000, "replay capacity in transitions, stored as whole episodes (FIFO)")
    n_batches: int = field(40, "gradient steps per iteration (Baselines' n_batches per cycle)")
    polyak: float = field(0.95, "target = polyak * target + (1 - polyak) * online, once per iteration")
    action_l2: float = field(1.0, "weight of the actor's mean squared action penalty")
    random_eps: float = field(0.3, "exploration: probability of a uniformly random action")
    noise_eps: float = field(0.2, "exploration: std of the Gaussian noise added to the actor's action")
    norm_eps: float = field(0.01, "std floor of the observation and goal normaliser")
    clip_obs: float = field(200.0, "observations and goals are clipped to +-clip_obs before normalising")

    def __post_init__(self):
        object.__setattr__(self, "hidden", tuple(int(w) for w in self.hidden))
        check(self.replay_k >= 0, "her.replay_k", self.replay_k, "an integer >= 0")
        check(0 <= self.gamma < 1, "her.gamma", self.gamma, "in [0, 1)")
        check(len(self.hidden) >= 1 and min(self.hidden) >= 1, "her.hidden", self.hidden, "one or more widths >= 1")
        check(self.actor_lr > 0, "her.actor_lr", self.actor_lr, "> 0")
        check(self.critic_lr > 0, "her.critic_lr", self.critic_lr, "> 0")
        check(self.batch_size >= 1, "her.batch_size", self.batch_size, "an integer >= 1")
        check(self.buffer_transitions >= 1, "her.buffer_transitions", self.buffer_transitions, "an integer >= 1")
        check(self.n_batches >= 0, "her.n_batches", self.n_batches, "an integer >= 0")
        check(0 <= self.polyak <= 1, "her.polyak", self.polyak, "in [0, 1]")
        check(self.action_l2 >= 0, "her.action_l2", self.action_l2, ">= 0")
        check(0 <= self.random_eps <= 1, "her.random_eps", self.random_eps, "in [0, 1]")
        check(self.noise_eps >= 0, "her.noise_eps", self.noise_eps, ">= 0")
        check(self.norm_eps > 0, "her.norm_eps", self.norm_eps, "> 0")
        check(self.clip_obs > 0, "her.clip_obs", self.clip_obs, "> 0")

    @property
    def future_p(self) -> float:
        return 1.0 - 1.0 / (1.0 + self.replay_k)
