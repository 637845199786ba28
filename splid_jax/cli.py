"""Command lines generated from frozen config dataclasses, so ``--help`` documents every field.

Light on purpose (JAX is imported only where used): the commands import it first, so that a
signal while JAX loads can already be handled."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import os
import re
import signal
import sys
import tempfile

_INTERRUPTED = {"when": ""}  # what a signal outside a run's own handlers cuts short, said in its line


def quiet_interrupts(when: str = "before the run started") -> None:
    """Outside a run's own handlers (before it, after it), SIGINT and SIGTERM end the process at once
    with one line and no traceback (exit 130 / 143): no write is under way that a stop could tear.
    ``when``: what the line says was cut short (``interrupts_now``)."""

    def stop(signum, frame):
        when = _INTERRUPTED["when"]
        os.write(2, f"interrupted ({signal.Signals(signum).name}){' ' + when if when else ''}\n".encode())
        os._exit(128 + signum)

    interrupts_now(when)
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, stop)


def interrupts_now(when: str) -> None:
    """What ``quiet_interrupts``' line says from now on, e.g. that the run is complete and whole."""
    _INTERRUPTED["when"] = when


def check_environment() -> None:
    """A MUJOCO_GL naming an OpenGL backend MuJoCo cannot load here (absent, or not one it knows) fails
    every command as MuJoCo is imported: one line naming the variable, exit 2."""
    gl = os.environ.get("MUJOCO_GL")
    if not gl:
        return
    try:
        import mujoco  # noqa: F401
    except Exception as e:
        print(f"error: MUJOCO_GL={gl!r}: MuJoCo cannot load that OpenGL backend here ({_first_line(e)}); unset it, "
              "or set egl or osmesa where its library is installed", file=sys.stderr)  # fmt: skip
        raise SystemExit(2) from None


def run_main(main) -> int:
    """``main()``, where a backend that JAX_PLATFORMS names but JAX cannot start here is one line naming
    the variable, exit 2 (JAX finds out at its first use of a device, before the run writes anything)."""
    try:
        return main()
    except (RuntimeError, AssertionError) as e:
        platforms = os.environ.get("JAX_PLATFORMS")
        if not platforms or not _from_backend_start(e):
            raise
        print(f"error: JAX_PLATFORMS={platforms!r}: JAX cannot start that backend here ({_first_line(e)}); "
              "unset it to use what this machine has", file=sys.stderr)  # fmt: skip
        return 2


def _from_backend_start(e: BaseException) -> bool:
    tb = e.__traceback__
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    where = tb.tb_frame.f_code.co_filename if tb is not None else ""
    return "Unable to initialize backend" in str(e) or where.endswith("xla_bridge.py")


def _first_line(e: BaseException) -> str:
    lines = str(e).strip().splitlines()
    return f"{type(e).__name__}: {lines[0][:200]}" if lines else type(e).__name__


class Parser(argparse.ArgumentParser):
    """No abbreviated flags (``--learning-rat`` is an error, not ``--learning-rate``), and an
    ``--env-options`` help that lists every task's fields, importing the tasks only when shown."""

    def __init__(self, **kw):
        super().__init__(allow_abbrev=False, **kw)

    def parse_known_args(self, args=None, namespace=None):
        """A value with a leading minus that argparse would take for a flag (``--values -1,2``) is joined to
        its flag (``--values=-1,2``), so that the value's own check names the flag."""
        words, joined = list(sys.argv[1:] if args is None else args), []
        takes_one = {o for a in self._actions if a.option_strings and a.nargs is None for o in a.option_strings}
        i = 0
        while i < len(words):
            word = words[i]
            if word in takes_one and i + 1 < len(words) and re.fullmatch(r"-[\d.][\d.,eE+\-]*", words[i + 1]):
                joined.append(f"{word}={words[i + 1]}")
                i += 2
            else:
                joined.append(word)
                i += 1
        return super().parse_known_args(joined, namespace)

    def error(self, message: str):
        """The mistake in one line and where the usage is, not the whole usage before it."""
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")

    def format_help(self) -> str:
        listings = {"env_options": task_fields}
        for action in self._actions:
            if action.dest in listings and not getattr(action, "fields_listed", False):
                action.help = f"{action.help}. Fields and defaults: {listings[action.dest]()}".replace("%", "%%")
                action.fields_listed = True
        return super().format_help()


def flag_error(err, parser: argparse.ArgumentParser) -> str:
    """An ``InvalidConfig`` as the user typed it: ``invalid --iterations 3: must be a multiple of
    --eval-every 5``. Settings that are no flag of ``parser`` keep their own names; any other error is its
    own message."""
    from splid_jax.common.errors import InvalidConfig

    if not isinstance(err, InvalidConfig):
        return str(err)
    flags = {option for action in parser._actions for option in action.option_strings}
    # a positional argument shows as its name in the usage line (``RUN_DIR``); one of several by its singular
    positional = {}
    for a in parser._actions:
        if not a.option_strings:
            positional[a.dest] = a.metavar or a.dest.upper()
            if a.nargs in ("+", "*") and a.dest.endswith("s"):
                positional[a.dest[:-1]] = positional[a.dest]

    def flag(name: str) -> str | None:
        typed = "--" + name.replace(".", "-").replace("_", "-")
        return typed if typed in flags else positional.get(name)

    def named(match: re.Match) -> str:
        return f"{flag(match[1])} {match[2]}" if flag(match[1]) else match[0]

    def typed(text: str) -> str:
        return re.sub(r"\b([a-z][a-z0-9]*(?:[._][a-z0-9]+)*)=([^\s,;()]+)", named, text)

    if str(err) != f"invalid {err.field}={err.value!r}: must be {err.allowed}":  # a message of its own
        return typed(str(err))
    value = ",".join(map(str, err.value)) if isinstance(err.value, tuple | list) else err.value
    value = "(unset)" if value is None else value
    if not str(value) or not str(value).isprintable() or str(value).encode(errors="replace").decode() != str(value):
        value = repr(value)  # empty, or a name no terminal shows as typed: quoted, with its escapes
    head = f"{flag(err.field)} {value}" if flag(err.field) else f"{err.field}={err.value!r}"
    if not flag(err.field) and _options_flag(err.field, flags):  # a key of an options text: as it was typed
        head = f"{_options_flag(err.field, flags)} {err.field.partition('.')[2]}={value}"
    return f"invalid {head}: must be {typed(err.allowed)}"


def _options_flag(field: str, flags: set[str]) -> str | None:
    """The flag whose ``KEY=VALUE`` text holds ``field`` (``her.replay_k``: ``--her-options``; a task's
    ``push.substeps``: ``--env-options``), or None."""
    owner, dot, key = field.partition(".")
    if not dot or not key:
        return None
    if f"--{owner}-options" in flags:
        return f"--{owner}-options"
    import envs

    return "--env-options" if "--env-options" in flags and owner in envs.names() else None


def readers(name: str) -> str | None:
    """The learners that read run-config field ``name``, as an argument group's title; None for the
    run's own fields, which every learner reads."""
    from splid_jax.learners import registry

    who = [x.name for x in registry.LEARNERS.values() if name in x.reads or name == x.options]
    return f"read only by {', '.join(who)}" if who else None


def task_fields() -> str:
    """``task: field=default, ...`` for each task; a task with the previous one's fields names only
    the defaults that differ."""
    import envs

    parts, previous = [], None
    for name in envs.names():
        cls = envs.task_class(name)
        defaults = {f.name: _marked(f) for f in dataclasses.fields(cls)}
        if previous is not None and previous[1].keys() == defaults.keys():
            diff = {k: v for k, v in defaults.items() if v != previous[1][k]}
            shown = ", ".join(f"{k}={v}" for k, v in diff.items())
            parts.append(f"{name}: as {previous[0]}" + (f" but {shown}" if shown else ""))
        else:
            parts.append(f"{name}: " + ", ".join(f"{k}={v}" for k, v in defaults.items()))
            previous = (name, defaults)
    return "; ".join(parts)


def _marked(f: dataclasses.Field) -> str:
    """A task field's default, marked when the field is an experimental option."""
    return f"{f.default} (experimental)" if f.metadata.get("experimental") else f"{f.default}"


def _int_tuple(text: str) -> tuple[int, ...]:
    try:
        return tuple(int(w) for w in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated integers, got {text!r}") from None


_TYPES = {"int": int, "float": float, "str": str, "str | None": str, "tuple[int, ...]": _int_tuple}


def settings_of(cls) -> tuple[dataclasses.Field, ...]:
    """A config dataclass's settings as its flags name them (``TrainConfig``'s flat, with the cloning ones)."""
    return cls.settings_fields() if hasattr(cls, "settings_fields") else dataclasses.fields(cls)


def add_config_flags(
    parser: argparse.ArgumentParser,
    cls,
    per_task: dict[str, dict] | None = None,
    exclude: frozenset[str] = frozenset(),
    per_algo: dict[str, dict[str, dict]] | None = None,
) -> None:
    """One flag per field (less ``exclude``); every default is None so that explicit values can be told
    apart. ``per_algo``: a learner's own defaults per task, shown after the task defaults they replace.
    Fields that only some learners read are listed in a group per set of learners (``readers``)."""
    groups: dict[str, argparse._ArgumentGroup] = {}
    for f in settings_of(cls):
        if f.name in exclude:
            continue
        flag = "--" + f.name.replace("_", "-")
        help_text = f.metadata.get("help", "")
        if f.default is not None:
            help_text += f" (default: {f.default})"
        elif per_task and any(f.name in d for d in per_task.values()):
            shown = ", ".join(f"{task} {_show(d[f.name])}" for task, d in per_task.items() if f.name in d)
            for algo, tasks in (per_algo or {}).items():
                values: dict[str, list[str]] = {}
                for task, d in tasks.items():
                    if f.name in d:
                        values.setdefault(_show(d[f.name]), []).append(task)
                shown += "".join(f"; {algo} on {', '.join(ts)}: {v}" for v, ts in values.items())
            help_text += f" (default per task: {shown})"
        title = readers(f.name)
        where = parser if title is None else groups.setdefault(title, parser.add_argument_group(title))
        if f.type == "bool":
            where.add_argument(flag, action=argparse.BooleanOptionalAction, default=None, help=help_text)
        else:
            where.add_argument(flag, type=_TYPES[f.type], default=None, help=help_text, metavar=f.name.upper())


def refuse_unread(given: dict, algo: str, namespace: argparse.Namespace | None = None) -> None:
    """A setting given on the command line that ``algo`` does not read is a mistake, not a no-op; one of
    another learner's own flags (``add_learner_flags``) is named as typed (``--her-batch-size``)."""
    from splid_jax.common.errors import InvalidConfig
    from splid_jax.learners import registry

    for key, value in vars(namespace or argparse.Namespace()).items():
        options, _, name = key.partition(":")
        owner = next((x for x in registry.LEARNERS.values() if name and x.options == options), None)
        if owner is not None and value is not None and owner.name != algo:
            field = f"{options.removesuffix('_options')}_{name}"
            raise InvalidConfig(field, value, f"unset unless --algo {owner.name} (this run's is {algo})")
    learner = registry.get(algo)
    for name in registry.ignores(algo):
        if name in given:
            own = f"--{learner.options.replace('_', '-')}" if learner.options else "the flags of its group in --help"
            allowed = f"unset with --algo {algo}, which does not read it (its own settings: {own})"
            raise InvalidConfig(name, given[name], allowed)


def _show(value) -> str:
    return ",".join(map(str, value)) if isinstance(value, tuple) else str(value)


def add_learner_flags(parser: argparse.ArgumentParser) -> None:
    """One flag per field of each learner's own settings dataclass (``--her-batch-size``), in that learner's
    group; ``explicit_values`` gathers them into the learner's options text (``her_options``)."""
    from splid_jax.learners import registry

    for learner in registry.LEARNERS.values():
        if learner.options is None:
            continue
        group = parser.add_argument_group(f"{learner.name}'s own settings (read only by {learner.name})")
        prefix = learner.options.removesuffix("_options")
        for f in dataclasses.fields(learner.settings):
            flag, dest = f"--{prefix}-{f.name.replace('_', '-')}", f"{learner.options}:{f.name}"
            help_text = f"{f.metadata.get('help', '')} (default: {_show(f.default)})".replace("%", "%%")
            if f.type == "bool":
                group.add_argument(flag, dest=dest, action=argparse.BooleanOptionalAction, help=help_text)
            else:
                group.add_argument(flag, dest=dest, type=_TYPES[f.type], help=help_text, metavar=f.name.upper())


def explicit_values(cls, namespace: argparse.Namespace) -> dict:
    """The settings given on the command line; a learner's own flags (``add_learner_flags``) join its
    options text, after those ``--her-options`` gives."""
    names = {f.name for f in settings_of(cls)}
    given = {k: v for k, v in vars(namespace).items() if k in names and v is not None}
    for key, value in vars(namespace).items():
        options, _, name = key.partition(":")
        if name and value is not None and options in names:
            shown = str(value).lower() if isinstance(value, bool) else _show(value)
            given[options] = ",".join(filter(None, (given.get(options), f"{name}={shown}")))
    return given


def default_compile_cache() -> str:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "splid_jax", "jax")


def _cache_dir(path: str) -> str:
    """A directory that programs can be written to, made here if need be: JAX would only warn, program by
    program, of one it cannot use. The default, where it cannot be written, is turned off with a notice."""
    if not path:
        return path
    here = os.path.abspath(path)
    while not os.path.exists(here):
        here = os.path.dirname(here)
    if not os.path.isdir(here):
        raise argparse.ArgumentTypeError(f"{path!r} is not a directory ({here} is a file); '' turns the cache off")
    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except OSError as e:
        why = f"cannot be written ({e.strerror})"
        if path != default_compile_cache():
            raise argparse.ArgumentTypeError(f"{path!r} {why}; '' turns the cache off") from None
        print(f"the compile cache {path} {why}: compiling without it", file=sys.stderr)
        return ""
    return path


def add_compile_cache_flag(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--compile-cache",
        metavar="DIR",
        type=_cache_dir,
        default=default_compile_cache(),
        help="keep compiled programs in DIR, so a rerun with the same task and shapes skips most of "
        "its compilation ('' turns it off; default: %(default)s). On a CPU, one run with its progress display on "
        "compiles its training program anew each time, as JAX keeps no program that calls back to the host for "
        "the lines inside a chunk: --quiet keeps it",
    )


def use_compile_cache(path: str) -> None:
    """JAX's persistent compilation cache: MJX programs take tens of seconds to compile and are
    the same from one run of a setting to the next."""
    import jax

    if path:  # programs that compile in under a second are not kept (JAX's default threshold)
        jax.config.update("jax_compilation_cache_dir", path)


def add_launch_flags(parser: argparse.ArgumentParser) -> None:
    """How this process joins the others of a run over several processes or hosts: launch options,
    not settings, so they change nothing a run computes and a resume may give them anew."""
    group = parser.add_argument_group("several processes (one sweep over several hosts)")
    group.add_argument("--coordinator", metavar="HOST:PORT", help="address of process 0, which every process reaches")
    group.add_argument("--num-processes", type=int, metavar="N", help="processes of the run (default: 1)")
    group.add_argument("--process-id", type=int, metavar="I", help="this process's index in [0, N); 0 writes the run")


def start_processes(ns: argparse.Namespace) -> None:
    """Joins the run's processes (``jax.distributed``) before any other JAX use; bad launch options
    raise ``InvalidConfig`` before anything waits for a peer."""
    from splid_jax.runtime import multihost

    show = (lambda text: None) if getattr(ns, "quiet", False) else (lambda text: print(text, flush=True))
    multihost.start(multihost.launch(ns.coordinator, ns.num_processes, ns.process_id), show)


def exit_with(code: int) -> None:
    """Exit with ``code``; after a signal (130, 143) at once: the chunk or compilation the signal cut
    short may still run in a worker thread. Otherwise the work is done, and a signal while Python shuts
    down (which puts the default handlers back, so the process would die by it, silently) is ignored."""
    if code in (130, 143):
        with contextlib.suppress(OSError, ValueError):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(code)
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_IGN)
    raise SystemExit(code)
