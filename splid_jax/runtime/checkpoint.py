"""Checkpoints of the whole training state, so a killed run resumes bit-exactly.

Layout: ``RUN_DIR/checkpoints/<step>/{state,meta,digest}``. Orbax writes each step
into a temporary directory and renames it only once complete, so a save killed
half-way leaves no step behind (the leftover is removed by the next ``save``).
Orbax stores no checksums, and a flipped byte in a data file can decode without
error, so a CRC32 of every leaf is stored too and checked on restore.
"""

from __future__ import annotations

import errno
import json
import logging
import math
import os
import re
import sys
import zlib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import jax
import numpy as np
import orbax.checkpoint as ocp

MAX_TO_KEEP = 3

_STATE, _META, _DIGEST = "state", "meta", "digest"
_MISSING = object()


class CheckpointError(RuntimeError):
    """A checkpoint is absent, unreadable or does not fit the run resuming from it."""


class NoSpace(CheckpointError):
    """The disk filled up while the run wrote; its last whole checkpoint is kept."""


class WriteFailed(CheckpointError):
    """A write into the run directory failed (read-only, no permission); its last whole checkpoint is kept."""


# What a write into the run directory may fail with, besides a full disk, that the user must fix.
WRITE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM, errno.EIO})
_OS_ERROR_CODE = re.compile(r"os_error_code='?(\d+)")  # how tensorstore names the errno in its messages


def write_failure(e: BaseException | None) -> tuple[int, str] | None:
    """``(errno, reason)`` where ``e``, or an error it was raised from, is a filesystem refusing a write
    (orbax and tensorstore wrap it); None for any other error."""
    seen = 0
    while e is not None and seen < 20:
        if isinstance(e, OSError) and e.errno in WRITE_ERRNOS:
            return e.errno, e.strerror + (f": {e.filename}" if e.filename else "")
        found = _OS_ERROR_CODE.search(str(e))
        if found and int(found.group(1)) in WRITE_ERRNOS:
            return int(found.group(1)), os.strerror(int(found.group(1)))
        if "No space left on device" in str(e):
            return errno.ENOSPC, os.strerror(errno.ENOSPC)
        e, seen = e.__cause__ or e.__context__, seen + 1
    return None


def is_no_space(e: BaseException | None) -> bool:
    """Whether ``e``, or an error it was raised from, is a full disk (orbax and tensorstore wrap it)."""
    failure = write_failure(e)
    return failure is not None and failure[0] in (errno.ENOSPC, errno.EDQUOT)


class _OrbaxThreadErrors(logging.Filter):
    """Drops orbax's log of an error in one of its writer threads, with its traceback: the same error
    reaches ``save``'s caller, which reports it in one line."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not (record.exc_info and "orbax" in record.pathname)


def quiet_closed_loops(hook):
    """``sys.unraisablehook`` less tensorstore's callbacks into the event loop of an orbax write that
    failed and closed it (one traceback each, from its own threads): the failure itself is reported."""

    def unraisablehook(unraisable):
        value = unraisable.exc_value
        if not (isinstance(value, RuntimeError) and str(value) == "Event loop is closed"):
            hook(unraisable)

    return unraisablehook


logging.getLogger("absl").addFilter(_OrbaxThreadErrors())
sys.unraisablehook = quiet_closed_loops(sys.unraisablehook)


def checkpoint_dir(run_dir: str | Path) -> Path:
    return Path(run_dir).absolute() / "checkpoints"  # orbax needs absolute paths


def _manager(directory: Path, *, read_only: bool, max_to_keep: int = MAX_TO_KEEP) -> ocp.CheckpointManager:
    # Synchronous saves keep Ctrl-C handling simple: when save() returns, the step is on disk.
    # One process saves and restores the whole state, also when a sweep spans several (splid_jax.runtime.multihost):
    # orbax is told it works alone, else it waits at barriers for the others; it then leaves the mkdir to us.
    if not read_only:
        directory.mkdir(parents=True, exist_ok=True)
    alone = ocp.options.MultiprocessingOptions(primary_host=jax.process_index(), active_processes={jax.process_index()})
    options = ocp.CheckpointManagerOptions(
        max_to_keep=max_to_keep,
        create=False,
        cleanup_tmp_directories=not read_only,
        enable_async_checkpointing=False,
        multiprocessing_options=alone,
    )
    handlers = {
        _STATE: ocp.StandardCheckpointHandler(),
        _META: ocp.JsonCheckpointHandler(),
        _DIGEST: ocp.JsonCheckpointHandler(),
    }
    return ocp.CheckpointManager(directory, options=options, item_handlers=handlers)


def _flat(tree: Any) -> dict[str, Any]:
    """Leaves keyed by orbax's own dotted names (``opt.0.mu.w``), the keys its metadata uses."""
    flat = ocp.tree.to_flat_dict(ocp.tree.serialize_tree(tree, keep_empty_nodes=False))
    return {".".join(str(k) for k in path): leaf for path, leaf in flat.items()}


def on_host(state: Any) -> Any:
    """``state`` with host arrays, as orbax stores it (nested dicts of the same key names): what one
    process saves of arrays that others computed. Through a custom node such as brax's UInt64 host
    arrays turn back into device arrays, which orbax refuses to save when a run spans processes."""
    return jax.tree.map(np.asarray, ocp.tree.serialize_tree(jax.device_get(state), keep_empty_nodes=True))


def _crc(x: Any) -> int:
    return zlib.crc32(np.ascontiguousarray(np.asarray(x)))


def _digest(state: Any) -> dict[str, list]:
    return {path: [str(np.asarray(x).dtype), _crc(x)] for path, x in _flat(state).items()}


def _one_line(e: BaseException) -> str:
    lines = str(e).strip().splitlines()
    first = lines[0].split(" See full TensorStore details")[0] if lines else ""
    return f"{type(e).__name__}: {first[:200]}"


def save(
    run_dir: str | Path, step: int, state: Any, meta: Mapping[str, Any], *, max_to_keep: int = MAX_TO_KEEP
) -> bool:
    """Write ``state`` and ``meta`` as checkpoint ``step``; keep the newest ``max_to_keep``.

    Returns False without writing when ``step`` is already saved (a final save that
    coincides with a periodic one). A step older than the newest saved one raises,
    because orbax would silently skip it and the run would later resume from the
    wrong, newer checkpoint.
    """
    step = int(step)
    meta = json.loads(json.dumps(dict(meta)))  # fail before writing anything; keep it as it will read back
    directory = checkpoint_dir(run_dir)
    with _manager(directory, read_only=False, max_to_keep=max_to_keep) as mngr:
        latest = mngr.latest_step()
        if latest is not None and step < latest:
            raise CheckpointError(f"refusing to save step {step} in {directory}: it already holds newer step {latest}")
        if step == latest:
            return False
        args = ocp.args.Composite(
            **{
                _STATE: ocp.args.StandardSave(state),
                _META: ocp.args.JsonSave(meta),
                _DIGEST: ocp.args.JsonSave(_digest(state)),
            }
        )
        if not mngr.save(step, args=args, force=True):
            raise CheckpointError(f"orbax declined to save step {step} in {directory}")
        mngr.wait_until_finished()
    return True


def latest_step(run_dir: str | Path) -> int | None:
    directory = checkpoint_dir(run_dir)
    if not directory.is_dir():
        return None
    with _manager(directory, read_only=True) as mngr:
        return mngr.latest_step()


def _first_meta_diff(saved: Any, expected: Any, key: str = "") -> tuple[str, Any, Any] | None:
    """First differing dotted key with both values; nested dicts are walked so the key is precise.
    Only the keys of ``expected`` are checked: the saved meta may carry more (progress, timings)."""
    if isinstance(saved, dict) and isinstance(expected, dict):
        for k in expected:
            sub = f"{key}.{k}" if key else str(k)
            if k not in saved:
                return sub, _MISSING, expected[k]
            diff = _first_meta_diff(saved[k], expected[k], sub)
            if diff is not None:
                return diff
        return None
    if isinstance(saved, list) and isinstance(expected, list) and len(saved) == len(expected):
        same = all(_first_meta_diff(s, e) is None for s, e in zip(saved, expected, strict=True))
        return None if same else (key, saved, expected)
    if isinstance(saved, float) and isinstance(expected, float) and math.isnan(saved) and math.isnan(expected):
        return None
    if saved == expected and isinstance(saved, bool) == isinstance(expected, bool):
        return None
    return key, saved, expected


def _show(value: Any) -> str:
    return "<absent>" if value is _MISSING else repr(value)


def _kind(dtype: np.dtype) -> str:
    return "i" if dtype.kind in "iu" else dtype.kind


def _dtype(x: Any) -> np.dtype:
    dtype = getattr(x, "dtype", None)
    return np.dtype(dtype) if dtype is not None else np.asarray(x).dtype


def _check_layout(saved: dict[str, Any], like: dict[str, Any]) -> str | None:
    """Name the first leaf whose presence, shape or dtype differs; None when all agree."""
    for path, want in like.items():
        if path not in saved:
            return f"leaf '{path}' of like_state is not in the checkpoint"
        have = saved[path]
        have_shape, want_shape = tuple(getattr(have, "shape", ())), tuple(np.shape(want))
        have_dtype, want_dtype = _dtype(have), _dtype(want)
        # Python scalars are stored as 64-bit; an abstract template (eval_shape) sees them as 32-bit.
        scalar = isinstance(have, ocp.metadata.ScalarMetadata) or isinstance(want, int | float | bool)
        dtype_ok = _kind(have_dtype) == _kind(want_dtype) if scalar else have_dtype == want_dtype
        if have_shape != want_shape or not dtype_ok:
            return (
                f"leaf '{path}' is {have_shape} {have_dtype} in the checkpoint "
                f"but {want_shape} {want_dtype} in like_state"
            )
    extra = [p for p in saved if p not in like]
    if extra:
        return f"checkpoint leaf '{extra[0]}' is not in like_state"
    return None


def _restore_target(like_state: Any) -> Any:
    """Concrete arrays become shape/dtype/sharding stubs; numpy scalars, which orbax cannot target, 0-d arrays.
    An abstract leaf without a sharding is placed on this process's first device: orbax would otherwise take the
    saved one, which names a device of the machine that trained (a GPU's checkpoint evaluated on a CPU)."""
    local = jax.sharding.SingleDeviceSharding(jax.local_devices()[0])

    def target(x: Any) -> Any:
        if isinstance(x, jax.Array):
            return ocp.utils.to_shape_dtype_struct(x)
        if isinstance(x, jax.ShapeDtypeStruct) and x.sharding is None:
            return jax.ShapeDtypeStruct(x.shape, x.dtype, sharding=local)
        return np.asarray(x) if isinstance(x, np.generic) else x

    return jax.tree.map(target, like_state)


class Rotated(CheckpointError):
    """The checkpoint being read was removed meanwhile: the run writing it kept newer ones instead."""


def restore(
    run_dir: str | Path,
    like_state: Any,
    expect_meta: Mapping[str, Any] | None = None,
    step: int | None = None,
) -> tuple[int, Any, dict[str, Any]]:
    """Load checkpoint ``step`` (default: newest) into the structure, shapes and dtypes of ``like_state``.

    ``like_state`` may be concrete or abstract (``jax.eval_shape``). Returns ``(step, state, meta)``.
    ``expect_meta`` must match the saved meta (its keys; the saved meta may hold more).
    Every failure is a one-line ``CheckpointError`` so the trainer can print it and stop. The newest
    checkpoint of a run still training may be rotated out while it is read: the then newest is read.
    """
    last = MAX_TO_KEEP + 1
    for attempt in range(last + 1):
        try:
            return _restore(run_dir, like_state, expect_meta, step)
        except Rotated:
            if step is not None or attempt == last:
                raise
        except FileNotFoundError as e:  # a step removed while orbax listed the steps
            if step is not None or attempt == last:
                why = f"the checkpoints in {checkpoint_dir(run_dir)} changed while read ({_one_line(e)})"
                raise Rotated(why) from e
    raise AssertionError("unreachable")


def _read_meta(mngr: ocp.CheckpointManager, step: int) -> Any:
    return mngr.restore(step, args=ocp.args.Composite(**{_META: ocp.args.JsonRestore()}))[_META]


def _check_meta(meta: dict, expect_meta: dict | None, where: str) -> None:
    if expect_meta:
        diff = _first_meta_diff(meta, json.loads(json.dumps(dict(expect_meta))))
        if diff is not None:
            key, have, want = diff
            raise CheckpointError(f"{where} was saved with {key}={_show(have)} but {key}={_show(want)} is expected")


def check_meta(run_dir: str | Path, step: int, expect_meta: dict, meta: dict | None) -> None:
    """A resume's settings against its checkpoint's (``meta``, from ``saved_meta``), before anything is compiled:
    an edited config.json is refused in a moment, not after the compile. A meta that cannot be read is left to
    ``restore``."""
    if meta is not None:
        _check_meta(meta, expect_meta, f"checkpoint {checkpoint_dir(run_dir) / str(step)}")


def saved_meta(run_dir: str | Path, step: int) -> dict | None:
    """The settings a checkpoint was saved with; None where they cannot be read (``restore`` says why)."""
    try:
        with _manager(checkpoint_dir(run_dir), read_only=True) as mngr:
            meta = _read_meta(mngr, step)
    except Exception:
        return None
    return meta if isinstance(meta, dict) else None


def _restore(run_dir, like_state, expect_meta, step) -> tuple[int, Any, dict[str, Any]]:
    directory = checkpoint_dir(run_dir)
    if not directory.is_dir():
        raise CheckpointError(f"no checkpoint in {directory}: directory does not exist")
    with _manager(directory, read_only=True) as mngr:
        steps = sorted(mngr.all_steps())
        if not steps:
            raise CheckpointError(f"no checkpoint in {directory}")
        if step is None:
            step = steps[-1]
        elif int(step) not in steps:
            raise CheckpointError(f"no checkpoint for step {step} in {directory} (have {steps})")
        step = int(step)
        where = f"checkpoint {directory / str(step)}"
        others = [s for s in steps if s != step]

        def corrupt(reason: BaseException | str) -> CheckpointError:
            if not (directory / str(step)).is_dir():
                return Rotated(f"{where} was removed while it was read (the run writing it rotated it out)")
            reason = _one_line(reason) if isinstance(reason, BaseException) else reason
            hint = f"; other steps: {others}" if others else ""
            return CheckpointError(f"{where} is corrupt or unreadable ({reason}){hint}")

        try:
            meta = _read_meta(mngr, step)
        except Exception as e:
            raise corrupt(e) from e
        if not isinstance(meta, dict):
            raise corrupt(f"meta is {type(meta).__name__}, not a dict")
        _check_meta(meta, expect_meta, where)

        try:
            saved_leaves = _flat(mngr.item_metadata(step)[_STATE].tree)
        except Exception as e:
            raise corrupt(e) from e
        problem = _check_layout(saved_leaves, _flat(like_state))
        if problem is not None:
            raise CheckpointError(f"{where} does not match like_state: {problem}")

        try:
            items = mngr.restore(
                step,
                args=ocp.args.Composite(
                    **{_STATE: ocp.args.StandardRestore(_restore_target(like_state)), _DIGEST: ocp.args.JsonRestore()}
                ),
            )
        except Exception as e:
            raise corrupt(e) from e

    state, digest = items[_STATE], items[_DIGEST]
    restored = _flat(state)
    if not isinstance(digest, dict) or set(digest) != set(restored):
        raise corrupt("checksum list does not match the saved leaves")
    for path, x in restored.items():
        dtype, crc = digest[path]
        if _crc(np.asarray(x).astype(dtype, copy=False)) != crc:
            raise corrupt(f"leaf '{path}' fails its CRC32 check")
    return step, state, meta
