"""The documentation site (mkdocs.yml, docs/): it builds strictly, its command-line reference
lists every command of ``joulepath --help``, the tutorials' marked commands run as written on the
emulated robot, and its pages render in headless Chromium (navigation, code blocks, figure)."""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
from importlib import metadata
from pathlib import Path

import matplotlib
import matplotlib.image
import numpy as np
import pytest

from joulepath.cli import main

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
TUTORIALS = sorted(p for p in (DOCS / "tutorials").glob("*.md") if p.name != "index.md")
CHECK = re.compile(r"<!-- check -->\s*\n```bash\n(.*?)```", flags=re.S)
REQUIRES = re.compile(r"<!-- check-requires: ([\w.-]+) -->")  # a distribution (an extra's package)


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The site built strictly (a warning, a broken link or a missing page fails it)."""
    pytest.importorskip("mkdocs", reason="the docs extra: pip install -e '.[docs]'")
    pytest.importorskip("mkdocstrings")
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    built = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file", str(ROOT / "mkdocs.yml")]
        + ["--site-dir", str(out)],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        timeout=600,
    )
    assert built.returncode == 0, built.stderr[-4000:]
    assert "WARNING" not in built.stderr, built.stderr[-4000:]
    return out


def _listed_commands(capsys: pytest.CaptureFixture[str]) -> list[str]:
    """The command names in the Commands panel of ``joulepath --help``."""
    assert main(["--help"]) == 0
    text = capsys.readouterr().out
    panel = text[text.index("Commands") :]
    return re.findall(r"^│ (\S+) {2,}", panel, flags=re.M)


def test_cli_reference_lists_every_command(site, capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "200")
    names = _listed_commands(capsys)
    assert {"optimize", "cycle", "robot", "rapid"} <= set(names)
    index = (site / "reference" / "cli" / "index.html").read_text(encoding="utf-8")
    for name in names:
        page = site / "reference" / "cli" / name / "index.html"
        assert page.is_file(), f"no reference page for `joulepath {name}`"
        assert f'href="{name}/"' in index, f"the CLI index does not link `joulepath {name}`"
        assert f"joulepath {name}" in page.read_text(encoding="utf-8")


def test_cli_reference_lists_every_option(site):
    import typer.main

    from joulepath.cli._main import app

    group = typer.main.get_command(app)
    root = group.context_class(group, info_name="joulepath")
    for name in group.list_commands(root):
        cmd = group.get_command(root, name)
        html = (site / "reference" / "cli" / name / "index.html").read_text(encoding="utf-8")
        ctx = cmd.context_class(cmd, info_name=name, parent=root)
        subs = [cmd.get_command(ctx, s) for s in getattr(cmd, "list_commands", lambda _c: [])(ctx)]
        for command in [cmd, *subs]:
            for param in command.params:
                for opt in param.opts if param.param_type_name == "option" else []:
                    assert f"<code>{opt}</code>" in html, f"`joulepath {name}`: {opt} is not on its page"


def _checked_commands(page: Path) -> list[str]:
    """The page's commands marked as a check, one string per (continued) line."""
    lines = []
    for block in CHECK.findall(page.read_text(encoding="utf-8")):
        for line in block.replace("\\\n", " ").splitlines():
            if line.strip() and not line.lstrip().startswith("#"):
                lines.append(line.strip())
    return lines


@pytest.mark.parametrize("page", TUTORIALS, ids=[p.stem for p in TUTORIALS])
def test_tutorial_checked_commands_run(page, tmp_path, monkeypatch, capsys):
    """Every command marked ``<!-- check -->`` in a tutorial runs as written, in order, in a scratch
    folder beside the repository's ``examples/``, and exits 0."""
    commands = _checked_commands(page)
    assert commands, f"{page.name} marks no command as a check"
    for dist in REQUIRES.findall(page.read_text(encoding="utf-8")):
        try:
            metadata.distribution(dist)
        except metadata.PackageNotFoundError:
            pytest.skip(f"{dist} (an optional extra) is not installed")
    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
    for line in commands:
        argv = shlex.split(line, comments=True)
        assert argv[0] == "joulepath", f"{page.name}: a checked command must be a joulepath command: {line}"
        code = main(argv[1:])
        captured = capsys.readouterr()
        assert code == 0, f"{page.name}: `{line}` exited {code}: {captured.err[-1500:]}"


# --------------------------------------------------------------------- rendering in a browser
PROBE = """<script>
window.addEventListener('load', () => {
  const shown = el => { const r = el.getBoundingClientRect(); return r.width > 0 && r.height > 0; };
  const out = {
    nav: [...document.querySelectorAll('.md-nav--primary .md-nav__link')].filter(shown).length,
    code: [...document.querySelectorAll('pre code')].filter(shown).length,
    highlighted: document.querySelectorAll('.highlight pre code span').length,
    code_font: document.querySelector('pre code') ?
      getComputedStyle(document.querySelector('pre code')).fontFamily : '',
    images: [...document.querySelectorAll('article img')].map(img => ({
      src: img.getAttribute('src'), complete: img.complete, natural: img.naturalWidth,
      shown: img.getBoundingClientRect().width})),
    header: document.querySelector('.md-header') ? shown(document.querySelector('.md-header')) : false,
    width: document.documentElement.scrollWidth,
  };
  const pre = document.createElement('pre');
  pre.id = 'render-check';
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>"""


def _chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


def _browser(browser: str, *args: str) -> subprocess.CompletedProcess[str]:
    with tempfile.TemporaryDirectory() as profile:
        return subprocess.run(
            [browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run"]
            + ["--disable-background-networking", "--disable-component-update", "--disable-sync"]
            + [f"--user-data-dir={profile}", "--window-size=1280,900", "--virtual-time-budget=10000"]
            + list(args),
            capture_output=True,
            text=True,
            timeout=180,
            check=False,
        )


@pytest.mark.parametrize("page", ["index.html", "tutorials/abb-move/index.html"])
def test_site_page_renders_in_headless_chromium(site, page, tmp_path):
    browser = _chromium()
    if browser is None:
        if os.environ.get("JOULEPATH_REQUIRE_BROWSER"):
            pytest.fail("JOULEPATH_REQUIRE_BROWSER is set but no chromium is installed")
        pytest.skip("no headless Chromium (Debian: apt-get install chromium)")
    source = site / page
    probe = source.with_name("render-check.html")  # beside it, so relative assets resolve
    probe.write_text(source.read_text(encoding="utf-8").replace("</body>", PROBE + "</body>"), "utf-8")
    done = _browser(browser, "--dump-dom", probe.as_uri())
    assert done.returncode == 0, done.stderr[-2000:]
    start = done.stdout.index('<pre id="render-check">') + len('<pre id="render-check">')
    raw = done.stdout[start : done.stdout.index("</pre>", start)]
    result = json.loads(raw.replace("&quot;", '"').replace("&amp;", "&"))
    assert result["header"] and result["nav"] >= 10, result
    assert result["code"] >= 1 and result["highlighted"] > 0 and "mono" in result["code_font"].lower(), result
    assert result["images"], "no figure on the page"
    for image in result["images"]:
        assert image["complete"] and image["natural"] > 100 and image["shown"] > 100, image
    assert result["width"] <= 1280, "the page scrolls sideways"

    shot = tmp_path / "page.png"
    done = _browser(browser, f"--screenshot={shot}", source.as_uri())
    assert done.returncode == 0 and shot.is_file(), done.stderr[-2000:]
    pixels = matplotlib.image.imread(shot)[..., :3]
    not_white = np.any(pixels < 0.95, axis=-1).mean()
    colours = np.unique((pixels * 255).astype(np.uint8).reshape(-1, 3), axis=0).shape[0]
    assert 0.03 < not_white < 0.9 and colours > 50, (not_white, colours)


def test_api_reference_has_a_page_per_public_module():
    """Every public module of joulepath (its stages and foundation) has a page in the Python API
    reference, and the page is in the navigation of mkdocs.yml."""
    import pkgutil

    import joulepath

    public = sorted(m.name for m in pkgutil.iter_modules(joulepath.__path__) if not m.name.startswith("_"))
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    for name in public:
        if name == "cli":  # the command line has its own, generated reference
            continue
        page = DOCS / "reference" / "api" / f"{name}.md"
        assert page.is_file(), f"joulepath.{name} has no page in docs/reference/api/"
        assert f"::: joulepath.{name}" in page.read_text(encoding="utf-8")
        assert f"reference/api/{name}.md" in nav, f"docs/reference/api/{name}.md is not in mkdocs.yml's nav"


def _documented_command_lines() -> list[tuple[str, str]]:
    """``(page, line)`` of every ``joulepath ...`` line in the bash blocks of docs/ and of the
    README (continued lines joined)."""
    found = []
    for page in [*sorted(DOCS.rglob("*.md")), ROOT / "README.md"]:
        for block in re.findall(r"```bash\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.S):
            for line in block.replace("\\\n", " ").splitlines():
                if line.strip().startswith("joulepath "):
                    found.append((str(page.relative_to(ROOT)), line.strip()))
    return found


def test_documented_commands_and_options_exist():
    """Every ``joulepath`` command line in the docs and the README names a real command and only its
    real options."""
    import typer.main

    from joulepath.cli._main import app

    group = typer.main.get_command(app)
    root = group.context_class(group, info_name="joulepath")
    lines = _documented_command_lines()
    assert len(lines) > 30
    assert sum(page == "README.md" for page, _ in lines) >= 8, "the README's quick starts"
    for page, line in lines:
        argv = shlex.split(line.replace("<PC address>", "HOST"), comments=True)[1:]
        cmd, ctx = group, root
        while argv and hasattr(cmd, "list_commands") and not argv[0].startswith("-"):
            name = argv.pop(0)
            assert name in cmd.list_commands(ctx), f"{page}: no command {name!r} in `{line}`"
            cmd = cmd.get_command(ctx, name)
            ctx = cmd.context_class(cmd, info_name=name, parent=ctx)
        known = {o for p in cmd.params for o in (*p.opts, *p.secondary_opts)} | {"--help", "--debug"}
        for token in argv:
            if token.startswith("--"):
                assert token.split("=")[0] in known, f"{page}: `{line}` has no option {token}"


def test_exit_codes_page_lists_every_work_limit():
    """docs/reference/exit-codes.md states each work limit with its variable and its default."""
    from joulepath._work import WORK_LIMITS

    page = (DOCS / "reference" / "exit-codes.md").read_text(encoding="utf-8")
    for name, limit in WORK_LIMITS.items():
        row = re.search(rf"^\| `{name.upper()}` \| ([\d.]+) \|", page, flags=re.M)
        assert row, f"exit-codes.md has no row for JOULEPATH_MAX_{name.upper()}"
        assert float(row.group(1)) == limit.default, (name, row.group(1), limit.default)
