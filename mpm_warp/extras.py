"""The optional packages behind the commands: a missing one is named in one line with the extra that brings it.

The command line's error handler (:func:`mpm_warp.cli.main`) asks :func:`missing_module` whether an error is
a missing package and prints :func:`missing_line`; ``mpm-warp field`` and ``sweep`` check theirs up front
(:func:`require`), since a batch would otherwise meet a missing package only when it scores or dispatches.
"""

from __future__ import annotations

import importlib

__all__ = ["EXTRAS", "COMMAND_EXTRA", "CORE", "extra_for", "missing_module", "missing_line", "require"]

#: pip extra -> the top-level modules it brings (pyproject.toml's [project.optional-dependencies]; tested)
EXTRAS = {
    "sweep": ("dask", "distributed"),
    "profile": ("snowprofile", "pandas", "snowpylot"),
    "weac": ("weac", "scipy"),
    "field": ("dask", "distributed", "weac", "scipy", "snowpylot", "snowprofile", "pandas", "sklearn"),
}

#: command -> the extra whose every module it imports before it starts
COMMAND_EXTRA = {"field": "field", "sweep": "sweep"}

#: top-level module -> its distribution, for the packages of the plain install (``pip install mpm-warp``)
CORE = {"warp": "warp-lang", "numpy": "numpy", "h5py": "h5py", "pyvista": "pyvista", "vtkmodules": "vtk",
        "matplotlib": "matplotlib", "PIL": "pillow", "tomli": "tomli"}


def extra_for(module: str, command: str | None = None) -> str | None:
    """The extra that brings top-level ``module``: the command's own extra when it has one that does, else the
    first extra that does, else None (a package of the plain install, or one no extra names)."""
    own = COMMAND_EXTRA.get(command)
    if own is not None and module in EXTRAS[own]:
        return own
    return next((extra for extra, mods in EXTRAS.items() if module in mods), None)


def missing_module(exc: BaseException) -> str | None:
    """The top-level name of the package whose absence ``exc`` reports, else None.

    ``exc`` reports one when it, or the error it was raised from (``raise ... from``), is an ImportError that
    names its module: a :class:`ModuleNotFoundError`, or one of the library's own (e.g.
    :class:`~mpm_warp.scenes.weac_reference.WeacUnavailable`) that sets ``name``. mpm_warp's own modules are
    never reported: a missing one is a fault of the install or of the code, not a missing extra.
    """
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        name = getattr(exc, "name", None) if isinstance(exc, ImportError) else None
        if name and (isinstance(exc, ModuleNotFoundError) or type(exc).__module__.startswith("mpm_warp")):
            top = name.split(".")[0]
            return None if top == "mpm_warp" else top
        exc = exc.__cause__
    return None


def missing_line(command: str, module: str) -> str:
    """The one line for ``mpm-warp COMMAND`` when ``module`` is missing: the package, and how to install it.

    Examples
    --------
    >>> missing_line("field", "distributed")
    'mpm-warp field: needs the \\'distributed\\' package; install it with pip install "mpm-warp[field]"'
    """
    extra = extra_for(module, command)
    if extra is not None:
        how = f'pip install "mpm-warp[{extra}]"'
    elif module in CORE:
        how = f"pip install {CORE[module]} (a dependency of mpm-warp)"
    else:
        return f"mpm-warp {command}: needs the '{module}' package, which is not installed"
    return f"mpm-warp {command}: needs the '{module}' package; install it with {how}"


def require(command: str) -> None:
    """Import every module of ``command``'s extra (:data:`COMMAND_EXTRA`); a command without one needs nothing.

    Raises
    ------
    ModuleNotFoundError
        The first module that is not installed (its ``name`` is the module).
    """
    for module in EXTRAS.get(COMMAND_EXTRA.get(command), ()):
        importlib.import_module(module)
