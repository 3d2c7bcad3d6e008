"""The API reference's pages, made from the package itself: one page per
module, headed by its name, and per package a page that introduces it and
lists its modules (no hand-kept list of modules).  ``docs/conf.py`` writes
them into ``docs/api/`` before a build; ``tests/test_doctests.py`` checks
that every module has its page."""
import os
import pkgutil

import skfem_pg

#: the subpackages in the order the data flows (mesh -> particles ->
#: ... -> solver -> output); the rest follow alphabetically
FLOW = ["discretization", "formulations", "materials", "solvers",
        "distributed", "analysis", "scenes"]


def modules():
    """``{name: is_package}`` of every module of the package (the data
    package of ``.geo`` sources left out)."""
    out = {"skfem_pg": True}
    for m in pkgutil.walk_packages(skfem_pg.__path__, "skfem_pg."):
        if not m.name.startswith("skfem_pg.meshes"):
            out[m.name] = m.ispkg
    return out


def children(package, found):
    """The modules and packages directly in ``package``, packages first
    (in :data:`FLOW` order), then modules alphabetically."""
    depth = package.count(".") + 1
    direct = [n for n in found if n.startswith(package + ".")
              and n.count(".") == depth]

    def key(name):
        last = name.rsplit(".", 1)[1]
        flow = FLOW.index(last) if last in FLOW else len(FLOW)
        return (not found[name], flow, last)
    return sorted(direct, key=key)


def pages():
    """``{file name: reST text}`` of the reference's pages."""
    found = modules()
    out = {}
    for name, is_package in found.items():
        title = "``{}``".format(name)
        text = [title, "=" * len(title), "", ".. automodule:: " + name]
        if is_package:
            text += ["   :no-members:", "", ".. toctree::",
                     "   :maxdepth: 1", ""]
            text += ["   " + c for c in children(name, found)]
        out[name + ".rst"] = "\n".join(text) + "\n"
    return out


def write(folder):
    """Write :func:`pages` into ``folder`` (a page rewritten only when it
    changed, so that Sphinx rebuilds only those), removing stale ones."""
    os.makedirs(folder, exist_ok=True)
    wanted = pages()
    for name in os.listdir(folder):
        if name.endswith(".rst") and name not in wanted:
            os.remove(os.path.join(folder, name))
    for name, text in wanted.items():
        path = os.path.join(folder, name)
        if not os.path.exists(path) or open(path).read() != text:
            tmp = path + ".tmp"
            with open(tmp, "w") as fh:
                fh.write(text)
            os.replace(tmp, path)
