"""The harness of the demos and benchmarks (not part of the package):
their command line (``--out``, ``--quick``, ``--results``), where they
write, the measured tables they write into ``benchmarks/README.md``,
wall time to an accuracy and error-against-time plots.

A demo imports it as ``harness`` (``python demos/NAME.py`` puts this
folder on ``sys.path``); the benchmarks through ``benchmarks/harness.py``.

A *row* is a dict with at least ``method``, ``err`` and the time split
``preprocess``, ``assemble``, ``solve`` (as in
:attr:`skfem_pg.scenes.Result.times`).
"""
import argparse
import os
import re
import shutil
import tempfile

from skfem_pg import threads


def output_dir(path=None, create=True):
    """Where demos and benchmarks write: ``path`` (their ``--out``), else
    ``$SKFEM_PG_OUT``, else ``./out`` under the current directory — never
    the installed package or the source tree.  Created if missing (unless
    ``create=False``)."""
    path = path or os.environ.get("SKFEM_PG_OUT") or os.path.join(
        os.getcwd(), "out")
    path = os.path.abspath(path)
    if create:
        os.makedirs(path, exist_ok=True)
    return path


class _ShowDefaults(argparse.ArgumentDefaultsHelpFormatter):
    """argparse's default display, except where the help text says the
    default itself or there is none to say (flags, ``None``)."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text or action.default in (None, False) \
                or action.default is argparse.SUPPRESS:
            return text
        return super()._get_help_string(action)


def demo_parser(doc, results=False, quick=True):
    """The ``argparse`` parser of a demo or benchmark: its description is
    the first paragraph of ``doc`` (a whole sentence), every option's
    default is shown; ``--out`` (:func:`output_dir`), ``--quick``
    (the demo's seconds-long variant, run by the tests; not with
    ``quick=False``, for a script that has none) and, with
    ``results``, ``--results`` (a markdown page whose section of this
    script :func:`update_results` rewrites)."""
    ap = argparse.ArgumentParser(
        description=plain_text(" ".join(doc.strip().split("\n\n")[0]
                                        .split())),
        formatter_class=_ShowDefaults)
    ap.add_argument("--out", help="output directory (default: "
                    "$SKFEM_PG_OUT or ./out)")
    if quick:
        ap.add_argument("--quick", action="store_true",
                        help="a short run on small node sets (seconds; "
                        "about a minute for the explicit fracture demos, "
                        "which run several models to their first "
                        "failures), what tests/test_demos.py runs; the "
                        "numbers it prints are not the demo's claims")
    if results:
        ap.add_argument("--results", help="markdown page whose section of "
                        "this script is rewritten (e.g. "
                        "benchmarks/README.md)")
    return ap


def plain_text(text):
    """``text`` without reST markup, for a terminal: roles
    (``:func:`~a.b.c``` -> ``c``, ``:func:`a.b``` -> ``a.b``), literals
    and emphasis.

    >>> plain_text(":func:`~skfem_pg.newton` and ``--quick`` *now*")
    'newton and --quick now'
    """
    text = re.sub(r":[\w:]+:`~[^`]*?([^.`]+)`", r"\1", text)
    text = re.sub(r":[\w:]+:`([^`]+)`", r"\1", text)
    text = re.sub(r"``([^`]+)``", r"\1", text)
    return re.sub(r"(?<![\w*])\*([^*\s][^*]*)\*(?![\w*])", r"\1", text)


def write_atomically(path, text):
    """Write ``text`` to ``path`` through a temporary file in the same
    folder and ``os.replace``: the page is never half written, and keeps
    its permissions."""
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(os.path.abspath(path)),
                               suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        if os.path.exists(path):
            shutil.copymode(path, tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def update_results(path, section, text):
    """Replace the section ``section`` of the markdown results page
    ``path`` (between ``<!-- begin NAME -->`` and ``<!-- end NAME -->``)
    with ``text``, or append it: the benchmarks write their own measured
    tables, so the page cannot drift from what the code does.  Returns
    the path written, or ``None`` (with a printed note) if it cannot be
    written — e.g. an installed copy without the source tree."""
    import datetime
    begin, end = ("<!-- begin {} -->".format(section),
                  "<!-- end {} -->".format(section))
    stamp = "*{}; {}.*".format(datetime.date.today().isoformat(),
                               threads.describe())
    block = "{}\n{}\n\n{}\n{}".format(begin, text.strip(), stamp, end)
    try:
        old = open(path).read() if os.path.exists(path) else ""
        if begin in old and end in old:
            head, rest = old.split(begin, 1)
            new = head + block + rest.split(end, 1)[1]
        else:
            new = old.rstrip() + "\n\n" + block + "\n"
        write_atomically(path, new)
    except OSError as err:
        print("could not update {} ({})".format(path, err))
        return None
    return path


def markdown_table(header, rows):
    """A markdown table from a header and rows of already formatted
    cells."""
    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join(" ---: " for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


def wall_time(row):
    """Preprocess + assemble + solve seconds of a row."""
    return row["preprocess"] + row["assemble"] + row["solve"]


def first_within(rows, method, target):
    """The first row (node set) of ``method`` from which on its ``err``
    stays at most ``target`` in every later row (an error that crosses
    zero on its way is not yet converged), or None."""
    sel = [r for r in rows if r["method"] == method]
    hit = None
    for r in reversed(sel):
        if r["err"] > target:
            break
        hit = r
    return hit


def print_time_to_target(rows, methods, target=0.01, what="error"):
    """Print, per method, the wall time of the first row (node set) from
    which on its ``err`` stays at most ``target`` (:func:`first_within`)."""
    print("\nwall time to reach {:g} % {} (first node set from which on "
          "it stays there):"
          .format(100 * target, what))
    for name in methods:
        hit = first_within(rows, name, target)
        if hit:
            print("  {:24s} {:7.3f} s ({} nodes)".format(
                name, wall_time(hit), hit["nodes"]))
        else:
            print("  {:24s} not reached".format(name))


def plot_error_vs_time(ax, rows, styles, ylabel, title, target=0.01):
    """Log-log error against wall time, one line per method in ``styles``
    (``{method: matplotlib format}``), with a horizontal line at
    ``target``."""
    for name, st in styles.items():
        sel = [r for r in rows if r["method"] == name]
        ax.loglog([wall_time(r) for r in sel], [r["err"] for r in sel], st,
                  label=name)
    if target:
        ax.axhline(target, color="0.5", lw=0.8)
    ax.set_xlabel("wall time (preprocess + assemble + solve) [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()


def save_error_vs_time(fn, rows, styles, ylabel, title, target=0.01):
    """One-panel :func:`plot_error_vs_time` written to ``fn`` (PNG)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    plot_error_vs_time(ax, rows, styles, ylabel, title, target)
    fig.tight_layout()
    fig.savefig(fn, dpi=120)
    plt.close(fig)


def new_figure(ncols=1, figsize=(8, 4.5)):
    """``(fig, axes)`` of ``ncols`` side-by-side plots on matplotlib's
    file backend (demos write PNGs; no display needed); write it with
    :func:`save_figure`."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt.subplots(1, ncols, figsize=figsize)


def save_figure(fig, fn, dpi=120):
    """Tight layout, write ``fn`` (creating its folder), close, say so."""
    import matplotlib.pyplot as plt
    os.makedirs(os.path.dirname(os.path.abspath(fn)), exist_ok=True)
    fig.tight_layout()
    fig.savefig(fn, dpi=dpi)
    plt.close(fig)
    print("wrote", os.path.relpath(fn))
