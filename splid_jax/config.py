"""A run's configuration: one frozen dataclass, validated on construction, from which the command
line is generated (each field's ``help`` is its ``--help`` line) and which a run's config.json holds.

Its fields are the run's own settings (task, seed, budget, evaluation, checkpoints, devices) and each
learner's own as a frozen dataclass of their own (``cloning``) or options text (HER's, ES's). The command
line and config.json hold them flat, one level; ``presets`` gives those left unset; a setting that the
chosen learner does not read is refused on the command line."""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
import types
from typing import Any

import envs
from splid_jax import presets
from splid_jax.common.errors import check
from splid_jax.common.fields import field
from splid_jax.common.paths import is_utf8
from splid_jax.common.values import format_overrides, merged_options, parse_overrides
from splid_jax.learners import registry
from splid_jax.learners.her.config import DEFAULTS as HER_DEFAULTS
from splid_jax.learners.her.config import HerConfig
from splid_jax.learners.imitation.config import ImitationConfig

CLONING = frozenset(f.name for f in dataclasses.fields(ImitationConfig))
MAX_ITERATIONS = 10**7  # far beyond any run's budget: a larger value is a typo, and would run for ever
# Keys a run's config.json holds beside the fields: where it ran, and the physics code it ran.
PROVENANCE = ("devices", "physics")
# Settings runs were once recorded with that left the package (experiments/NOTES.md, "Retired options"): a
# config.json holding one at its neutral value loads without it, one at another value is refused
RETIRED = {"hold_horizon": 0, "rest_horizon": 0, "select_radius": 1.0}


_KINDS = {
    "int": "an integer",
    "float": "a number",
    "bool": "true or false",
    "str": "a string",
    "str | None": "a string",
    "tuple[int, ...]": "a list of integers",
}


def _is_a(value: Any, kind: str) -> bool:
    """Whether ``value`` is of the field type named ``kind`` (a bool is no number here)."""
    if isinstance(value, bool):
        return kind == "bool"
    if kind == "int":
        return isinstance(value, numbers.Integral)
    if kind == "float":
        return isinstance(value, numbers.Real)
    if kind in ("str", "str | None"):
        return isinstance(value, str)
    if kind == "tuple[int, ...]":
        return isinstance(value, list | tuple) and all(_is_a(v, "int") for v in value)
    return True


@dataclasses.dataclass(frozen=True, init=False)
class TrainConfig:
    """Built from the settings flat (``TrainConfig(env="push", horizon=8)``), as the command line and
    config.json give them: the run's own are its fields, the cloning learners' go to ``cloning`` (read
    also as ``cfg.horizon``), HER's and ES's travel as options text."""

    env: str = field("point", "task: " + ", ".join(envs.names()))
    preset: str = field(
        "tuned",
        "the defaults the other settings start from: " + "; ".join(f"{k} ({v})" for k, v in presets.PRESETS.items()),
        recorded_when_set=True,
    )
    seed: int = field(
        0,
        "PRNG seed; the same seed gives the same run from the same compiled program (the compile cache keeps "
        "it); a fresh compilation on a GPU may pick other kernels and round differently",
    )
    iterations: int = field(None, "SPLID iterations (explore, select, behaviour cloning); a multiple of eval_every")
    num_envs: int = field(
        None,
        "episodes explored in parallel per iteration; es: not set, its population plays "
        "es.population x es.episodes_per_member episodes per generation",
    )
    algo: str = field("splid", "learner: " + ", ".join(f"{x.name} ({x.summary})" for x in registry.LEARNERS.values()))
    eval_every: int = field(None, "iterations per compiled chunk; evaluation, logging and checkpoints come between")
    eval_episodes: int = field(None, "episodes of the deterministic policy per evaluation")
    eval_subgoal_reach: float = field(
        None,
        "evaluations (and splid_jax.evaluate, splid_jax.rollout) give the policy a subgoal on the line to the goal, "
        "at most this far from the achieved goal (m on the Fetch tasks), and the goal once within it: far goals lie "
        "beyond those it was taught; success is judged at the goal. 0: the goal itself. Exploration steers only with "
        "explore_subgoal_reach",
        recorded_when_set=True,
        unrecorded=0.0,
    )
    checkpoint_every: int = field(1, "chunks between checkpoints (0: only at the end)")
    num_devices: int = field(
        1,
        "devices to split the work across: a sweep's members, or a run's envs (splid, gcsl, pchid); "
        "0: every device this process sees that the count divides (CPU or GPU)",
    )
    run_dir: str | None = field(
        None, "directory for config.json, metrics.jsonl and checkpoints (default runs/ENV-sSEED)"
    )
    env_options: str = field(
        None,
        "task fields as KEY=VALUE[,KEY=VALUE...], e.g. finger=capsule or substeps=20,timestep=0.002; "
        "the keys given replace the task's default options, the others stay (grasped_starts=0 turns "
        "pick_and_place's grasped training starts off)",
    )
    cloning: ImitationConfig = field(None, "the cloning learners' settings, given flat (ImitationConfig's fields)")
    her_options: str = field(
        "", "her only: HER's settings as KEY=VALUE[,KEY=VALUE...], as the --her-* flags give them to config.json"
    )
    her_defaults: str | None = field(
        None,
        "her only: the defaults her_options are read against: mrl (HerConfig's, the default) or baselines "
        "(HerConfig's BASELINES, HER's defaults when runs recorded without this setting were made)",
        recorded_when_set=True,
        unrecorded="baselines",
    )
    es_options: str = field(
        "", "es only: ES's settings as KEY=VALUE[,KEY=VALUE...], as the --es-* flags give them to config.json"
    )

    def __init__(self, **settings):
        cloning = settings.pop("cloning", None)  # as dataclasses.replace passes it, beside any flat changes
        if cloning is not None:
            settings = {**{f.name: getattr(cloning, f.name) for f in dataclasses.fields(cloning)}, **settings}
        unknown = sorted(set(settings) - {f.name for f in self.settings_fields()})
        if unknown:
            raise TypeError(f"TrainConfig got unknown settings: {', '.join(unknown)}")
        flat = types.SimpleNamespace(**{f.name: settings.get(f.name, f.default) for f in self.settings_fields()})
        _resolve(flat)
        for f in dataclasses.fields(self):
            if f.name != "cloning":
                object.__setattr__(self, f.name, getattr(flat, f.name))
        object.__setattr__(self, "cloning", ImitationConfig(**{name: getattr(flat, name) for name in CLONING}))

    def __getattr__(self, name: str):
        """The cloning learners' settings read as the run's (``cfg.horizon``), as the command line names them."""
        cloning = self.__dict__.get("cloning")
        if cloning is None or name not in CLONING:
            raise AttributeError(name)
        return getattr(cloning, name)

    @classmethod
    def settings_fields(cls) -> tuple[dataclasses.Field, ...]:
        """Every setting as the command line and config.json hold them: the run's and, flat, the cloning ones."""
        run = [f for f in dataclasses.fields(cls) if f.name != "cloning"]
        at = next(i for i, f in enumerate(run) if f.name == "eval_every")
        return (*run[:at], *dataclasses.fields(ImitationConfig), *run[at:])

    def env_overrides(self) -> dict[str, Any]:
        return parse_overrides(self.env_options)

    def make_env(self) -> envs.GoalEnv:
        """The task this run trains on: ``env`` with the fields ``env_options`` changes."""
        return envs.make(self.env, **self.env_overrides())

    def learner_config(self):
        """The learner's own settings (``ImitationConfig``, ``HerConfig``, ``EsConfig``), validated."""
        return registry.settings(self)

    def check_env(self, env: envs.GoalEnv) -> None:
        """Checks that need the task's sizes."""
        last = env.episode_length - 1
        check(self.horizon <= last, "horizon", self.horizon, f"an integer in [1, {last}] (below the episode length)")
        fingers = env.moves_fingers
        allowed = f"an integer in [1, {env.episode_length}]" if fingers else "1 on this task, whose fingers are locked"
        ok = self.gripper_hold <= (env.episode_length if fingers else 1)
        check(ok, "gripper_hold", self.gripper_hold, allowed)

    def to_json(self) -> dict[str, Any]:
        """The settings flat, as config.json holds them."""
        return {f.name: getattr(self, f.name) for f in self.settings_fields()}

    @classmethod
    def unrecorded_values(cls) -> dict[str, Any]:
        """What each setting added after runs were recorded reads as for those runs: how they behaved."""
        return {f.name: f.metadata["unrecorded"] for f in cls.settings_fields() if "unrecorded" in f.metadata}

    @classmethod
    def from_json(cls, saved: dict[str, Any], **changes) -> TrainConfig:
        """A config from a run's config.json, which also records the hardware it ran on. Its task options
        are whole, and kept as written (the checkpoint's record holds the same text): a run recorded before a
        task gained a default option resumes as it ran; a setting added since reads as those runs behaved
        (its ``unrecorded`` value)."""
        unrecorded = cls.unrecorded_values()
        if saved.get("algo") != "her":  # what HER's options were read against concerns HER's runs alone
            unrecorded.pop("her_defaults")
        for name, value in RETIRED.items():
            allowed = f"a run this version can resume: its {name}={saved.get(name)!r} left the package"
            check(saved.get(name, value) == value, "resume", saved.get("run_dir"), allowed)
        kept = {k: v for k, v in saved.items() if k not in PROVENANCE and k not in RETIRED}
        cfg = cls(**{**unrecorded, **kept, **changes})
        options = changes.get("env_options", saved.get("env_options"))
        if isinstance(options, str):  # checked by the construction above
            object.__setattr__(cfg, "env_options", options)
        return cfg


def _resolve(c) -> None:
    """Resolves a config's settings (``c``, flat and mutable) in place: the preset's defaults for those left
    at None, then every check, each naming its setting."""
    for f in TrainConfig.settings_fields():  # a config.json may hold any JSON: each value's type first
        value = getattr(c, f.name)
        check(value is None or _is_a(value, f.type), f.name, value, _KINDS.get(f.type, f.type))
    check(c.env in envs.names(), "env", c.env, "one of " + ", ".join(envs.names()))
    learner = registry.get(c.algo)
    if learner.settings is HerConfig:  # runs recorded before the setting read "baselines" (from_json)
        c.her_defaults = c.her_defaults or "mrl"
        check(c.her_defaults in HER_DEFAULTS, "her_defaults", c.her_defaults, " or ".join(HER_DEFAULTS))
    else:
        check(c.her_defaults is None, "her_defaults", c.her_defaults, "unset unless algo=her")
    for other in registry.LEARNERS.values():  # each learner's own settings, refused for another
        text = getattr(c, other.options) if other.options else ""
        check(not text or other is learner, other.options, text, f"empty unless algo={other.name}")
    if learner.sets_num_envs:  # ES: the population sets the episodes per generation
        es = registry.settings(c)
        per_generation = es.population * es.episodes_per_member
        check(
            c.num_envs in (None, per_generation),
            "num_envs",
            c.num_envs,
            f"unset with algo=es: its population plays es.population x es.episodes_per_member = "
            f"{per_generation} episodes per generation",
        )
        c.num_envs = per_generation
    check(c.preset in presets.PRESETS, "preset", c.preset, "one of " + ", ".join(presets.PRESETS))
    defaults = presets.defaults(c.env, learner.name, c.preset)
    options = {  # option by option: the preset's, then the given ones (their syntax is checked here, the
        # fields where the task is built)
        **parse_overrides(defaults.pop("env_options", "")),
        **parse_overrides(c.env_options or ""),
    }
    c.env_options = format_overrides(options)
    if defaults.get(learner.options or ""):  # the preset's own settings of the learner, the given ones on top
        text = merged_options(learner.settings, defaults.pop(learner.options), getattr(c, learner.options),
                              learner.options, learner.name)  # fmt: skip
        setattr(c, learner.options, text)
    if c.horizon_end is None:  # a task's falling horizon goes with its own H, not with one the caller set
        task_end = defaults["horizon_end"] if c.horizon is None else 0
        c.horizon_end = task_end if registry.reads(learner.name, "horizon_end") else 0
    if c.buffer_size is not None or c.buffer_window is not None:  # a task's window goes with its buffer
        for name in ("buffer_window", "buffer_window_grow"):
            if getattr(c, name) is None:
                setattr(c, name, 0)
    if not registry.reads(learner.name, "explore_subgoal_reach"):  # a task's steering is its cloning learners'
        defaults["explore_subgoal_reach"] = 0.0
    if not registry.reads(learner.name, "buffer_window"):  # as the window, which HER and ES do not read
        defaults.update(buffer_window=0, buffer_window_grow=0)
    for name, value in defaults.items():  # fill per-algorithm, then per-task defaults for fields left at None
        if getattr(c, name) is None:
            setattr(c, name, value)
    c.hidden = tuple(int(w) for w in c.hidden)
    check(0 <= c.seed < 2**32, "seed", c.seed, "an integer in [0, 2**32)")
    for f in TrainConfig.settings_fields():  # inf and nan pass every range check, and JSON cannot hold them
        if f.type == "float":
            check(math.isfinite(getattr(c, f.name)), f.name, getattr(c, f.name), "a finite number")
        if f.type == "bool":  # a string such as "False" would pass every truth test
            check(isinstance(getattr(c, f.name), bool), f.name, getattr(c, f.name), "true or false")
    in_range = 1 <= c.iterations <= MAX_ITERATIONS
    check(in_range, "iterations", c.iterations, f"an integer in [1, {MAX_ITERATIONS}]")
    check(c.num_envs >= 1, "num_envs", c.num_envs, "an integer >= 1")
    check(c.num_devices >= 0, "num_devices", c.num_devices, "an integer >= 0 (0: every device)")
    check(len(c.hidden) >= 1 and min(c.hidden) >= 1, "hidden", c.hidden, "one or more widths >= 1")
    check(c.horizon >= 1, "horizon", c.horizon, "an integer >= 1 (and < the episode length)")
    registry.settings(c)  # the learner's own settings, each checked against its range
    if learner.grows_horizon and c.pchid_every == 0:  # resolved once, so a resume keeps the schedule
        c.pchid_every = max(1, c.iterations // (2 * c.horizon))
    check(c.eval_every >= 1, "eval_every", c.eval_every, "an integer >= 1")
    check(
        c.iterations % c.eval_every == 0,
        "iterations",
        c.iterations,
        f"a multiple of eval_every={c.eval_every}",
    )
    check(c.eval_episodes >= 1, "eval_episodes", c.eval_episodes, "an integer >= 1")
    reach = c.eval_subgoal_reach
    check(reach >= 0, "eval_subgoal_reach", reach, "a distance >= 0 (0: no subgoals)")
    check(c.checkpoint_every >= 0, "checkpoint_every", c.checkpoint_every, "an integer >= 0")
    if c.run_dir is None:
        c.run_dir = os.path.join("runs", f"{c.env}-s{c.seed}")
    check(c.run_dir.strip() != "", "run_dir", c.run_dir, "a directory name, not empty")
    check(is_utf8(c.run_dir), "run_dir", c.run_dir, "a path of UTF-8 text (checkpoints are written by it)")
    check(not os.path.isfile(c.run_dir), "run_dir", c.run_dir, "a directory, not an existing file")
