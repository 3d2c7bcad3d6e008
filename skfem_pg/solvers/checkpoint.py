"""Checkpoints: a run's state in one ``.npz`` file, so that it can be
resumed after a crash and end where the uninterrupted run ends.

* :func:`save` / :func:`load`: the unknowns, the load factor reached and
  the committed history of a model, plus any further named state (the
  drivers store their step controller: :func:`~skfem_pg.solvers.newton`'s
  step and predictor, the integrators' time, velocities, accelerations and
  energy accounts).
* Writes are atomic: a temporary file in the same directory, then
  ``os.replace``; a kill during the write leaves the previous checkpoint
  intact.
* A checkpoint carries the fingerprint of its model (:func:`fingerprint`:
  formulation, material and its parameters, basis, the particle or node
  positions, the mesh's cells, counts) and the kind of run that wrote it
  (:data:`KINDS`); loading it into another model, or resuming it by
  another kind of driver, raises a ``ValueError`` naming what differs.
* :func:`save` checks what it writes: one finite value per unknown, a
  finite load factor (in [0, 1] for a static run) or time.
* ``path`` may be given with or without its ``.npz`` suffix.
"""
import json
import os
import time
import zipfile

import numpy as np
from ..io import atomic_write
from ..keys import digest, exact
from ..naming import name_of
from ..discretization.layout import is_family_basis
from ..formulations.protocol import require_model

#: bump when the stored content changes meaning (3: the mesh's cells in
#: the fingerprint, the driver kind; 4: the material by
#: :func:`skfem_pg.keys.exact`)
FORMAT = 4

#: the drivers that write checkpoints: ``"static"`` (:func:`~skfem_pg.
#: solvers.newton`, ``load`` a load factor), ``"newmark"`` and
#: ``"explicit"`` (:func:`~skfem_pg.solvers.newmark`,
#: :func:`~skfem_pg.solvers.central_difference`: ``load`` the time)
KINDS = ("static", "newmark", "explicit")
#: the drivers of :data:`KINDS`, for messages
RUNS = {"static": "a static run (newton)", "newmark": "a Newmark run",
        "explicit": "an explicit run (central_difference)"}


def npz_path(path):
    """``path`` as the file a checkpoint is written to: ``.npz`` appended
    unless it ends so (what ``np.savez`` would write)."""
    path = os.fspath(path)
    return path if path.endswith(".npz") else path + ".npz"


def fingerprint(model):
    """What a checkpoint must match, as ``{field: text}``: the
    formulation, its material (type and parameters, full precision), the
    basis (family basis: its thesis code; FE: the element), the node or
    particle positions (a hash), the cells of its mesh (a hash: another
    triangulation of the same vertices differs) and the number of
    unknowns."""
    basis = model.basis
    material = getattr(model, "material", None)
    material = getattr(material, "material", material)  # a History's law
    if is_family_basis(basis):
        try:
            kind = name_of(basis)
        except (KeyError, ValueError):
            kind = "FamilyBasis {}".format(getattr(basis, "shape", ""))
    else:
        kind = type(getattr(basis, "elem", basis)).__name__
    return {"formulation": type(model).__qualname__,
            "material": repr(exact(material)),
            "basis": kind,
            "positions": digest(basis.doflocs),
            "cells": _cells(basis),
            "unknowns": str(model.N)}


def _cells(basis):
    """A hash of the cells of the basis' mesh (``"none"`` without one)."""
    mesh = getattr(basis, "mesh", None)
    t = getattr(mesh, "t", None)
    if t is None:
        return "none"
    return digest(t)


def save(path, model, x, load=1.0, kind=None, **state):
    """Write ``x`` (all unknowns of ``model``), the load factor (or time)
    ``load``, the committed history of a plastic ``model``, the model's
    :func:`fingerprint`, the ``kind`` of run (:data:`KINDS`, or ``None``:
    any driver may resume it that finds its state) and ``state`` (further
    arrays or numbers, e.g. a driver's step controller) to ``path``
    atomically.  Returns the path written (with ``.npz``).

    Raises ``ValueError`` for ``x`` of another length than the model's
    unknowns or with non-finite entries, a non-finite ``load``, a static
    load factor outside [0, 1], a negative time, an unknown ``kind``."""
    path = npz_path(path)
    x = np.asarray(x, dtype=float)
    n = require_model(model, "checkpoint.save").N
    if x.shape != (n,):
        raise ValueError("checkpoint.save: x has shape {}, the model has {} "
                         "unknowns".format(x.shape, n))
    bad = np.flatnonzero(~np.isfinite(x))
    if len(bad):
        raise ValueError("checkpoint.save: x has {} non-finite entries "
                         "(first: unknown {} = {})".format(len(bad), bad[0],
                                                          x[bad[0]]))
    if kind is not None and kind not in KINDS:
        raise ValueError("checkpoint.save: kind must be one of {} or None, "
                         "got {!r}".format(", ".join(KINDS), kind))
    try:
        load = float(load)
    except (TypeError, ValueError):
        raise ValueError("checkpoint.save: load must be a number, got {!r}"
                         .format(load)) from None
    if not np.isfinite(load) or (kind == "static" and not 0 <= load <= 1) \
            or (kind in ("newmark", "explicit") and load < 0):
        raise ValueError(
            "checkpoint.save: load = {!r} is not a {}".format(
                load, "load factor in [0, 1]" if kind == "static"
                else "time >= 0" if kind else "finite number"))
    arrays = {"x": x, "load": load, "kind": kind or "",
              "format": FORMAT,
              "fingerprint": json.dumps(fingerprint(model), sort_keys=True)}
    h = getattr(model, "history", None)
    saved = None if h is None else h.save()
    for k, v in (saved or {}).items():
        arrays["history_" + k] = v
    for k, v in state.items():
        arrays["state_" + k] = v
    return atomic_savez(path, **arrays)


def atomic_savez(path, **arrays):
    """``numpy.savez`` to ``path`` atomically: a temporary file in the
    same directory, flushed to disk, then ``os.replace``."""
    return atomic_write(npz_path(path), lambda f: np.savez(f, **arrays))


def load(path, model, state=False, kind=None, needs=()):
    """Read a checkpoint of :func:`save` into ``model`` (its history) and
    return ``(x, load)``, or ``(x, load, state)`` with ``state=True`` (the
    dict of further named state).  A checkpoint of another model — its
    :func:`fingerprint` differs: formulation, material, basis, positions,
    cells, unknowns — raises ``ValueError`` naming the difference, and so
    do an unreadable file or one that is no checkpoint (naming its path),
    a checkpoint written by another ``kind`` of run than the one given
    (:data:`KINDS`), and one without the state entries ``needs``."""
    path = npz_path(path)
    try:
        with np.load(path) as f:
            data = {k: f[k] for k in f.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as err:
        raise ValueError("checkpoint {} cannot be read ({}: {})".format(
            path, type(err).__name__, err)) from None
    if "fingerprint" not in data or "x" not in data:
        raise ValueError(
            "{} is not a skfem-pg checkpoint (its arrays: {}); checkpoints "
            "are written by the drivers' checkpoint= or by "
            "skfem_pg.solvers.checkpoint.save".format(
                path, ", ".join(sorted(data)) or "none"))
    fmt = int(data["format"]) if "format" in data else 1
    if fmt != FORMAT:
        raise ValueError("checkpoint {} has format {} (an earlier "
                         "skfem-pg), this version reads {}: run again from "
                         "the start".format(path, fmt, FORMAT))
    written = str(data["kind"]) if "kind" in data else ""
    if kind is not None and written and written != kind:
        raise ValueError(
            "checkpoint {} was written by {}; {} cannot resume it".format(
                path, RUNS.get(written, written), RUNS.get(kind, kind)))
    missing = [k for k in needs if "state_" + k not in data]
    if missing:
        raise ValueError(
            "checkpoint {} lacks the state of {} ({}): it was not written "
            "by that driver".format(path, RUNS.get(kind, "this driver"),
                                    ", ".join(missing)))
    mine, theirs = fingerprint(model), json.loads(str(data["fingerprint"]))
    for k in ("unknowns", "formulation", "basis", "material", "positions",
              "cells"):
        if mine[k] != theirs.get(k):
            raise ValueError(
                "checkpoint {} was written for another model — {}: {} in "
                "the checkpoint, {} in this model".format(
                    path, k, theirs.get(k), mine[k]))
    x, lam = data["x"], float(data["load"])
    saved = {k[len("history_"):]: v for k, v in data.items()
             if k.startswith("history_")}
    h = getattr(model, "history", None)
    if saved and h is None:
        raise ValueError("checkpoint {} holds a history, the model's "
                         "material has none".format(path))
    if h is not None:
        mismatch = getattr(h, "mismatch", None)
        bad = (mismatch(saved) if mismatch is not None
               else history_mismatch(h.committed, saved))
        if bad:
            raise ValueError("checkpoint {}: {}".format(path, bad))
        h.restore(saved or None)
    if not state:
        return x, lam
    extra = {k[len("state_"):]: (v[()] if v.ndim == 0 else v)
             for k, v in data.items() if k.startswith("state_")}
    return x, lam, extra


def history_mismatch(committed, saved):
    """Why the ``saved`` history arrays cannot replace ``committed`` (a
    key whose shape differs), or ``None``."""
    for k in sorted(set(saved) & set(committed or ())):
        if saved[k].shape != np.shape(committed[k]):
            return "history {!r} of shape {}, the model's has {}".format(
                k, saved[k].shape, np.shape(committed[k]))
    return None


class Every:
    """Where and how often a driver writes its checkpoint: ``path``, every
    ``steps`` converged steps and/or every ``seconds`` of wall time (the
    first that comes); neither: every step.  Drivers take it as
    ``checkpoint=Every("run.npz", seconds=600)`` (a plain path means every
    step)."""

    def __init__(self, path, steps=None, seconds=None):
        if steps is not None and not (isinstance(steps, (int, np.integer))
                                      and steps >= 1):
            raise ValueError("steps must be a positive integer, got {!r}"
                             .format(steps))
        if seconds is not None and not (np.isfinite(seconds)
                                        and seconds > 0):
            raise ValueError("seconds must be a positive number, got {!r}"
                             .format(seconds))
        self.path, self.steps, self.seconds = npz_path(path), steps, seconds
        self._last_step, self._last_time = 0, None

    @classmethod
    def of(cls, spec):
        """``None``, a path or an :class:`Every`, as an :class:`Every`."""
        if spec is None or isinstance(spec, cls):
            return spec
        return cls(spec)

    def due(self, count):
        """Whether a checkpoint is due at converged step number
        ``count``."""
        now = time.monotonic()
        if self._last_time is None:
            self._last_time = now
        return (self.steps is None and self.seconds is None) or (
            self.steps is not None and count - self._last_step >= self.steps
        ) or (self.seconds is not None
              and now - self._last_time >= self.seconds)

    def write(self, count, model, x, load, **state):
        """Write the checkpoint (:func:`save`)."""
        save(self.path, model, x, load, **state)

    def save(self, count, model, x, load, **state):
        """:func:`save` if due at converged step number ``count``."""
        due = self.due(count)
        if due:
            self.write(count, model, x, load, **state)
            self._last_step, self._last_time = count, time.monotonic()
        return due
