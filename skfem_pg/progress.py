"""Progress output of long runs: one convention for every driver.

``verbose`` means the same in :func:`~skfem_pg.solvers.newton` (serial
and distributed), :func:`~skfem_pg.solvers.newmark`,
:func:`~skfem_pg.solvers.central_difference` and
:meth:`Scene.solve <skfem_pg.scenes.Scene.solve>`:

* ``True``: a line per load step (Newton) or per tenth of the simulated
  time (the integrators);
* ``False``: silent;
* ``"auto"`` (the default): silent while a run is short, and the lines from
  :data:`AUTO_SECONDS` on — a run longer than a few seconds shows its
  progress, a quick one prints nothing.
"""
import sys
import time

#: seconds after which a ``verbose="auto"`` run starts to print
AUTO_SECONDS = 3.0
VERBOSE = (True, False, "auto")


def check_verbose(verbose):
    """``verbose`` if it is one of :data:`VERBOSE`, else ``ValueError``."""
    if not any(verbose is v or (isinstance(v, str) and verbose == v)
               for v in VERBOSE):
        raise ValueError("verbose must be True, False or 'auto', got {!r}"
                         .format(verbose))
    return verbose


class Echo:
    """Print progress lines under the ``verbose`` convention (module
    docstring), counting from its creation."""

    def __init__(self, verbose="auto", stream=None):
        self.verbose = check_verbose(verbose)
        self.stream = stream
        self.t0 = time.perf_counter()

    @property
    def on(self):
        """Whether a line printed now is shown."""
        if self.verbose == "auto":
            return time.perf_counter() - self.t0 >= AUTO_SECONDS
        return bool(self.verbose)

    def __call__(self, text, flush=True):
        if self.on:
            print(text, file=self.stream or sys.stdout, flush=flush)


__all__ = ["AUTO_SECONDS", "Echo", "VERBOSE", "check_verbose"]
