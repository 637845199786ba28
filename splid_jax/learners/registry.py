"""Every learner by name: its own settings, how it is built, and what it can do. The command lines,
the run config, the host loop and the figures read this table; no other module spells the names.

Learners are imported when built (``"module:Class"``), as tasks are: the run config and ``--help``
need only the settings, and the learners' modules import the run config."""

from __future__ import annotations

import dataclasses
import importlib
from typing import Any

from splid_jax.common.errors import InvalidConfig, check
from splid_jax.common.values import merged_options, options_text, parse_options
from splid_jax.learners.es.config import EsConfig
from splid_jax.learners.her.config import DEFAULTS as HER_DEFAULTS
from splid_jax.learners.her.config import HerConfig
from splid_jax.learners.imitation.config import ImitationConfig


@dataclasses.dataclass(frozen=True)
class Learner:
    name: str
    summary: str  # one line for --algo's help
    algorithm: str  # "module:Class" of its ``learners.base.Algorithm``, built as Class(env, cfg[, mesh])
    settings: type  # its own frozen config dataclass
    options: str | None = None  # the run-config field carrying its settings as KEY=VALUE text, if any
    reads: tuple[str, ...] = ()  # other run-config fields of the learners' that it reads
    splits_envs: bool = False  # a single run may split its envs across devices (--num-devices)
    sweeps: tuple[str, ...] = ()  # run-config fields a sweep's members may hold apart (traced values)
    sets_num_envs: bool = False  # its settings fix the episodes per iteration: --num-envs is not read
    grows_horizon: bool = False  # the learning horizon grows 1, 2, ..., H over the run (PCHID's curriculum)
    clones_every_pair: bool = False  # every relabelled pair is cloned, without SELECT (GCSL)


IMITATION_FIELDS = tuple(f.name for f in dataclasses.fields(ImitationConfig))
# SELECT's settings, read by SPLID and PCHID; GCSL clones every relabelled pair and selects nothing
SELECT_FIELDS = ("horizon", "horizon_end", "select", "relabel", "select_lanes")
_CLONING = tuple(f for f in IMITATION_FIELDS if f not in (*SELECT_FIELDS, "gcsl_relabel", "pchid_every"))
_TRAINER = "splid_jax.learners.splid.trainer:Trainer"
_IMITATION = dict(
    settings=ImitationConfig,
    splits_envs=True,
    sweeps=(
        "sigma",
        "horizon",
        "horizon_end",
        "sigma_end",
        "learning_rate",
        "policy_ema",
        "gripper_hold",
        "explore_subgoal_reach",
        "bc_reuse",
        "held_share",
        "buffer_window",
        "buffer_window_grow",
    ),
)
LEARNERS: dict[str, Learner] = {
    learner.name: learner
    for learner in (
        Learner("splid", "Algorithm 2", _TRAINER, reads=(*_CLONING, *SELECT_FIELDS), **_IMITATION),
        Learner(
            "gcsl",
            "every relabelled pair cloned",
            _TRAINER,
            reads=(*_CLONING, "gcsl_relabel"),
            **_IMITATION,
            clones_every_pair=True,
        ),
        Learner(
            "pchid",
            "SPLID with the horizon grown 1..H, see --pchid-every",
            _TRAINER,
            reads=(*_CLONING, *(f for f in SELECT_FIELDS if f != "horizon_end"), "pchid_every"),  # its own curriculum
            **_IMITATION,
            grows_horizon=True,
        ),
        Learner(
            "her",
            "DDPG + HER",
            "splid_jax.learners.her.learner:HER",
            HerConfig,
            options="her_options",
        ),
        Learner(
            "es",
            "OpenAI-ES",
            "splid_jax.learners.es.learner:ES",
            EsConfig,
            options="es_options",
            reads=("hidden",),
            sets_num_envs=True,
        ),
    )
}


def names() -> list[str]:
    return list(LEARNERS)


def get(name: str) -> Learner:
    check(name in LEARNERS, "algo", name, "one of " + ", ".join(LEARNERS))
    return LEARNERS[name]


def settings(cfg) -> Any:
    """The learner's own settings from the run config ``cfg`` (a ``config.TrainConfig``), validated."""
    learner = get(cfg.algo)
    if learner.options is not None:
        text = getattr(cfg, learner.options)
        if learner.settings is HerConfig and HER_DEFAULTS[cfg.her_defaults]:  # recorded against other defaults
            base = options_text(HerConfig(), **HER_DEFAULTS[cfg.her_defaults])
            text = merged_options(HerConfig, base, text, learner.options, learner.name)
        return parse_options(learner.settings, text, learner.options, learner.name)
    return learner.settings(**{name: getattr(cfg, name) for name in IMITATION_FIELDS})  # resolved: flat or nested


def ignores(name: str) -> tuple[str, ...]:
    """The learners' run-config fields that learner ``name`` does not read: given with it, they are refused."""
    read = get(name).reads
    return tuple(f for f in IMITATION_FIELDS if f not in read)


def reads(name: str, field: str) -> bool:
    """Whether learner ``name`` reads run-config ``field``."""
    return field not in ignores(name) and not (field == "num_envs" and get(name).sets_num_envs)


def make_algorithm(cfg, env, mesh=None):
    """The learner ``cfg.algo`` names, built for ``env`` (its envs split across ``mesh`` where it can)."""
    learner = get(cfg.algo)
    module, cls_name = learner.algorithm.split(":")
    cls = getattr(importlib.import_module(module), cls_name)
    if learner.splits_envs:
        return cls(env, cfg, mesh)
    if mesh is not None:
        raise InvalidConfig("num_devices", cfg.num_devices, f"1 for a single {learner.name} run")
    return cls(env, cfg)
