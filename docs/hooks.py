"""MkDocs hooks: the command-line reference, generated from the typer app at build time.

One page per command that ``joulepath --help`` lists (a group such as ``robot`` gets one page
with a section per subcommand), written from the same click objects that print ``--help``: the
usage line, the help text, and every argument and option with its type, default and range.
The pages and their place in the navigation (the ``reference/cli/index.md`` entry of ``nav``)
are made here, so the reference cannot drift from the code.
"""

from __future__ import annotations

import dataclasses
import html
import importlib
import re
from typing import Any

import typer.main
from mkdocs.config.defaults import MkDocsConfig
from mkdocs.structure.files import File, Files
from mkdocs.structure.pages import Page

from joulepath.cli._main import app

CLI_DIR = "reference/cli"
CLI_INDEX = f"{CLI_DIR}/index.md"


def _root() -> tuple[Any, Any]:
    group = typer.main.get_command(app)
    return group, group.context_class(group, info_name="joulepath")


def commands() -> list[tuple[str, Any, Any]]:
    """``(name, command, context)`` of every command ``joulepath --help`` lists, in its order."""
    group, root = _root()
    found = []
    for name in group.list_commands(root):
        cmd = group.get_command(root, name)
        if cmd is not None and not getattr(cmd, "hidden", False):
            found.append((name, cmd, cmd.context_class(cmd, info_name=name, parent=root)))
    return found


def page_path(name: str) -> str:
    """The reference page of the top-level command ``name``, relative to ``docs/``."""
    return f"{CLI_DIR}/{name}.md"


def _text(value: str) -> str:
    """Help text as Markdown: HTML-escaped outside `code`, table pipes escaped."""
    parts = re.split(r"(`+[^`]*`+)", value)
    out = "".join(p if p.startswith("`") else html.escape(p, quote=False) for p in parts)
    return out.replace("|", "\\|").replace("\n", " ")


def _help_paragraphs(cmd: Any) -> str:
    text = (cmd.help or "").strip()
    paragraphs = [" ".join(p.split()) for p in re.split(r"\n\s*\n", text) if p.strip()]
    return "\n\n".join(_text(p).replace("\\|", "|") for p in paragraphs)


def _param_rows(cmd: Any, ctx: Any) -> list[str]:
    rows = []
    for param in cmd.params:
        if getattr(param, "hidden", False):
            continue
        record = param.get_help_record(ctx)
        if record is None:
            continue
        spec, help_text = record
        names = ", ".join(f"`{o}`" for o in param.opts)
        if param.secondary_opts:
            names += " / " + ", ".join(f"`{o}`" for o in param.secondary_opts)
        if param.param_type_name == "argument":
            names = f"`{param.name.upper()}`" + ("..." if param.nargs == -1 else "")
        metavar = re.search(r"<([^>]*)>", spec)  # "--moves <int range>"; a flag has none
        kind = f"`{metavar.group(1)}`" if metavar else "flag"
        rows.append(f"| {names} | {kind} | {_text(help_text)} |")
    return rows


def _usage(prefix: str, cmd: Any, ctx: Any) -> str:
    return " ".join([prefix, *cmd.collect_usage_pieces(ctx)])


def _command_section(prefix: str, cmd: Any, ctx: Any, level: int) -> list[str]:
    lines = [f"{'#' * level} `{prefix}`", "", _help_paragraphs(cmd), ""]
    lines += ["```text", _usage(prefix, cmd, ctx), "```", ""]
    rows = _param_rows(cmd, ctx)
    if rows:
        lines += ["| Argument / option | Type | Meaning |", "|---|---|---|", *rows, ""]
    return lines


def command_page(name: str, cmd: Any, ctx: Any) -> str:
    """The Markdown of one top-level command's page (a group: one section per subcommand)."""
    prefix = f"joulepath {name}"
    lines = _command_section(prefix, cmd, ctx, 1)
    for sub_name in getattr(cmd, "list_commands", lambda _ctx: [])(ctx):
        sub = cmd.get_command(ctx, sub_name)
        sub_ctx = sub.context_class(sub, info_name=sub_name, parent=ctx)
        lines += _command_section(f"{prefix} {sub_name}", sub, sub_ctx, 2)
    lines += ["Exit codes: see [Exit codes](../exit-codes.md).", ""]
    return "\n".join(lines)


def index_page() -> str:
    """The command-line reference's front page: every command with its one-line help."""
    group, root = _root()
    lines = [
        "# Command line",
        "",
        "Every command of `joulepath --help`, generated from the command-line app when the site is"
        " built. `joulepath COMMAND --help` prints the same in a terminal.",
        "",
        "```text",
        _usage("joulepath", group, root),
        "```",
        "",
        "| Root option | Meaning |",
        "|---|---|",
    ]
    for param in group.params:
        record = param.get_help_record(root)
        if record is not None:
            lines.append(f"| `{record[0]}` | {_text(record[1])} |")
    lines += ["", "| Command | What it does |", "|---|---|"]
    for name, cmd, _ctx in commands():
        lines.append(f"| [`{name}`]({name}.md) | {_text(cmd.get_short_help_str(200))} |")
    lines += ["", "Exit codes: see [Exit codes](../exit-codes.md).", ""]
    return "\n".join(lines)


def _nav_with_commands(nav: Any) -> Any:
    if isinstance(nav, list):
        return [_nav_with_commands(item) for item in nav]
    if isinstance(nav, dict):
        return {
            key: (
                [CLI_INDEX, *({f"joulepath {n}": page_path(n)} for n, _c, _x in commands())]
                if value == CLI_INDEX
                else _nav_with_commands(value)
            )
            for key, value in nav.items()
        }
    return nav


def on_config(config: MkDocsConfig) -> MkDocsConfig:
    """Put one navigation entry per command under the command-line reference."""
    config.nav = _nav_with_commands(config.nav)
    return config


def on_files(files: Files, config: MkDocsConfig) -> Files:
    """Add the generated command-line pages."""
    files.append(File.generated(config, CLI_INDEX, content=index_page()))
    for name, cmd, ctx in commands():
        files.append(File.generated(config, page_path(name), content=command_page(name, cmd, ctx)))
    return files


# ------------------------------------------------------------------ values and fields from the code
MARKER = re.compile(r"<!-- (value|fields|pairs): ([\w.]+) -->")
RST_LITERAL = re.compile(r"::(</p>)")
SPHINX_ROLE = re.compile(r":(?:func|class|mod|data|attr|meth|exc|obj):(<code>)~?")


def _lookup(dotted: str) -> Any:
    module, _, name = dotted.rpartition(".")
    try:
        return getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError) as err:
        raise ValueError(f"docs: {dotted} named in a page does not exist ({err})") from err


def _render_marker(match: re.Match[str]) -> str:
    kind, dotted = match.groups()
    obj = _lookup(dotted)
    if kind == "value":
        return ", ".join(f"`{v}`" for v in obj)
    if kind == "pairs":
        rows = [f"| {_text(a)} | {_text(b)} |" for a, b in obj]
        return "\n".join(["| What | The thesis → here |", "|---|---|", *rows])
    rows = [f"| `{f.name}` | `{f.type}` |" for f in dataclasses.fields(obj)]
    return "\n".join(["| Key | Type |", "|---|---|", *rows])


def on_page_markdown(markdown: str, page: Page, **_kwargs: Any) -> str:
    """Fill ``<!-- value: dotted.NAME -->`` (a tuple of names), ``<!-- fields: dotted.Class -->``
    (a dataclass's fields and types) and ``<!-- pairs: dotted.NAME -->`` (a tuple of pairs, as a
    two-column table) from the code."""
    return MARKER.sub(_render_marker, markdown)


RST_TABLE = re.compile(r"<p>(=+(?: +=+)+)\n(.*?)\n\1</p>", flags=re.S)


def _rst_table(match: re.Match[str]) -> str:
    """An RST simple table (rule, header, rule, rows, rule) as an HTML table; columns start where
    the rule's runs of ``=`` start, the last one takes the rest of the line."""
    starts = [m.start() for m in re.finditer(r"=+", match.group(1))]
    lines = match.group(2).split("\n")
    if len(lines) < 2 or not re.fullmatch(r"=+(?: +=+)+", lines[1]):
        return match.group(0)

    def cells(line: str, tag: str) -> str:
        bounds = [*starts[1:], None]
        row = "".join(f"<{tag}>{line[a:b].strip()}</{tag}>" for a, b in zip(starts, bounds, strict=True))
        return f"<tr>{row}</tr>"

    body = "".join(cells(line, "td") for line in lines[2:] if line.strip())
    return f"<table><thead>{cells(lines[0], 'th')}</thead><tbody>{body}</tbody></table>"


def on_page_content(content: str, **_kwargs: Any) -> str:
    """Turn what reStructuredText means in numpydoc docstrings, and Markdown does not, into HTML:
    Sphinx roles (``:func:``, ``:class:`` ...) lose their prefix, the ``::`` that introduces a
    literal block becomes ``:``, and a simple table becomes a table."""
    content = RST_TABLE.sub(_rst_table, content)
    return RST_LITERAL.sub(r":\1", SPHINX_ROLE.sub(r"\1", content))
