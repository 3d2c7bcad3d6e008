"""Checkpoints: the unknowns, the load factor reached and the committed
history of a model in one ``.npz`` file, so that a run can be resumed
(``newton(model, ..., u0=x, load0=load)`` after :func:`load`)."""
import numpy as np


def save(path, model, x, load=1.0):
    """Write ``x`` (all unknowns of ``model``), the load factor ``load``
    and the committed history of a plastic ``model`` to ``path``."""
    arrays = {"x": np.asarray(x, dtype=float), "load": float(load)}
    h = getattr(model, "history", None)
    saved = None if h is None else h.save()
    for k, v in (saved or {}).items():
        arrays["history_" + k] = v
    np.savez(path, **arrays)


def load(path, model):
    """Read a checkpoint of :func:`save` into ``model`` (its history) and
    return ``(x, load)``; a checkpoint of another model (number of
    unknowns, history points) raises."""
    with np.load(path) as f:
        x, lam = f["x"], float(f["load"])
        saved = {k[len("history_"):]: f[k] for k in f.files
                 if k.startswith("history_")}
    if x.shape != (model.N,):
        raise ValueError("checkpoint {} has {} unknowns, the model {}".format(
            path, x.shape[0], model.N))
    h = getattr(model, "history", None)
    if saved and h is None:
        raise ValueError("checkpoint {} holds a history, the model's "
                         "material has none".format(path))
    if h is not None:
        if h.committed is not None and saved and \
                saved["alpha"].shape != h.committed["alpha"].shape:
            raise ValueError("checkpoint {}: history at {} points, the model "
                             "has {}".format(path, saved["alpha"].shape,
                                             h.committed["alpha"].shape))
        h.restore(saved or None)
    return x, lam
