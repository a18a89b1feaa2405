"""The command-line reference in ``docs/scenarios.md`` and the README's command table, generated from the
argument parser (:func:`mpm_warp.cli.build_parser`): every subcommand with every argument, its default and
its help, so a flag added to the parser appears in the docs on the next ``python -m
mpm_warp.docgen``.
"""

from __future__ import annotations

import argparse
import re

__all__ = ["subcommands", "synopsis", "cli_lines", "readme_lines", "BEGIN", "END", "README_BEGIN", "README_END"]

BEGIN = "<!-- cli:begin -->"
END = "<!-- cli:end -->"
README_BEGIN = "<!-- cli-table:begin -->"
README_END = "<!-- cli-table:end -->"


def subcommands(parser: argparse.ArgumentParser) -> list[tuple[str, str, argparse.ArgumentParser]]:
    """``(name, help, parser)`` of every subcommand, in the order they were added."""
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    helps = {c.dest: c.help or "" for c in sub._choices_actions}
    return [(name, helps.get(name, ""), p) for name, p in sub.choices.items()]


def _arguments(p: argparse.ArgumentParser) -> list[argparse.Action]:
    return [a for a in p._actions if not isinstance(a, argparse._HelpAction)]


def _metavar(a: argparse.Action) -> str:
    if a.choices is not None and a.metavar is None:
        return "|".join(map(str, a.choices))
    if isinstance(a.metavar, tuple):
        return " ".join(a.metavar)
    return a.metavar or a.dest.upper()


def _spelled(a: argparse.Action) -> str:
    """The argument as it is typed: ``SCENARIO``, ``--out OUT``, ``--video [gif|mp4]``, ``--quiet``."""
    if not a.option_strings:
        return _metavar(a)
    flag = a.option_strings[-1]
    if a.nargs == 0:
        return flag
    if a.nargs == "?":
        return f"{flag} [{_metavar(a)}]"
    return f"{flag} {_metavar(a)}"


def synopsis(name: str, p: argparse.ArgumentParser, prog: str = "mpm-warp") -> str:
    """One line: the subcommand, its positional arguments, then every option in brackets."""
    parts = [prog, name]
    for a in _arguments(p):
        s = _spelled(a)
        if a.option_strings:
            s = f"[{s}]" + (" ..." if isinstance(a, argparse._AppendAction) else "")
        parts.append(s)
    return " ".join(parts)


def _default(a: argparse.Action) -> str:
    if not a.option_strings:
        return "required"
    if a.nargs == 0:
        return "off"
    if isinstance(a, argparse._AppendAction):
        return "none"
    if a.nargs == "?" and a.default is None:
        return f"off (`{a.const}` when given alone)"
    if a.default is None:
        m = re.search(r"\(default:? ([^);]*)", a.help or "")
        return m.group(1) if m else "none"
    if isinstance(a.default, (list, tuple)):
        return "`" + " ".join(map(str, a.default)) + "`"
    return f"`{a.default}`"


def cli_lines(parser: argparse.ArgumentParser) -> list[str]:
    """The lines of the command-line reference: per subcommand its synopsis and a table of its arguments."""
    out = [f"Generated from `mpm_warp.cli.build_parser()` by `python -m mpm_warp.docgen`; "
           f"`{parser.prog} COMMAND --help` prints the same.", ""]
    for name, help_, p in subcommands(parser):
        out += [f"### `{parser.prog} {name}`", "", help_[:1].upper() + help_[1:] + ".", "", "```",
                synopsis(name, p, parser.prog), "```", ""]
        args = _arguments(p)
        if args:
            out += ["| argument | default | what it does |", "|---|---|---|"]
            for a in args:
                cells = (f"`{_spelled(a)}`", _default(a), " ".join((a.help or "").split()))
                out.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
            out.append("")
    while out and out[-1] == "":
        out.pop()
    return out


def readme_lines(parser: argparse.ArgumentParser) -> list[str]:
    """The README's command table: each subcommand with its positional arguments, its help and its options."""
    out = ["| command | what it does | options |", "|---|---|---|"]
    for name, help_, p in subcommands(parser):
        pos = " ".join(_metavar(a) for a in _arguments(p) if not a.option_strings)
        opts = ", ".join(f"`{a.option_strings[-1]}`" for a in _arguments(p) if a.option_strings)
        out.append(f"| `{parser.prog} {name}{' ' + pos if pos else ''}` | {help_} | {opts} |")
    return out
