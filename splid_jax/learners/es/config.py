"""ES's own settings."""

from __future__ import annotations

import dataclasses

from splid_jax.common.errors import check
from splid_jax.common.fields import field

SHAPINGS = ("centered_rank", "standardize", "raw")  # evosax's fitness shaping functions, by name


@dataclasses.dataclass(frozen=True)
class EsConfig:
    """ES's own settings (errors name them ``es.FIELD``); SPLID's ``sigma`` and ``learning_rate`` in
    ``TrainConfig`` do not apply to ES, and its ``num_envs`` follows the population."""

    population: int = field(256, "ES population per generation (even when antithetic); each member plays its episodes")
    sigma: float = field(0.02, "std of the Gaussian parameter perturbations (Salimans et al.: 0.02)")
    learning_rate: float = field(0.01, "Adam learning rate on the ES gradient estimate")
    antithetic: bool = field(True, "antithetic sampling: members come in mirrored pairs theta +- sigma * eps")
    paired_episodes: bool = field(
        True,
        "antithetic pairs play the same starts and goals, so their returns differ by the perturbation only",
    )
    fitness_shaping: str = field("centered_rank", "fitness shaping: " + ", ".join(SHAPINGS))
    episodes_per_member: int = field(1, "episodes per member per generation; its fitness is their mean return")
    weight_decay: float = field(
        0.0, "L2 penalty on the member's parameters, subtracted from its return before shaping (0: none)"
    )

    def __post_init__(self):
        check(self.population >= 2, "es.population", self.population, "an integer >= 2")
        check(
            not self.antithetic or self.population % 2 == 0,
            "es.population",
            self.population,
            "an even integer with antithetic sampling",
        )
        check(self.sigma > 0, "es.sigma", self.sigma, "> 0")
        check(self.learning_rate > 0, "es.learning_rate", self.learning_rate, "> 0")
        check(
            self.fitness_shaping in SHAPINGS,
            "es.fitness_shaping",
            self.fitness_shaping,
            "one of " + ", ".join(SHAPINGS),
        )
        check(self.episodes_per_member >= 1, "es.episodes_per_member", self.episodes_per_member, "an integer >= 1")
        check(self.weight_decay >= 0, "es.weight_decay", self.weight_decay, ">= 0")
