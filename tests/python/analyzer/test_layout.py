"""Package layout of stridefix_common, stridefix_sim, stridefix_analyzer and stridefix_lab, checked on
the source with ``ast``.

(a) No import circle among their modules: every circle so far came from a CLI module hosting helpers
    that the modules below it imported back (bench.sil_pdr <-> bench.fusion, crowd.cli <->
    crowd.experiment). Function-level imports count; imports under ``if TYPE_CHECKING:`` do not
    (annotations only, never run).
(b) No module over :data:`MAX_LINES` lines, and no firmware C source or header either.
(c) CLI modules only register commands: nothing imports a ``*.cli`` module (the console scripts
    ``stridefix_analyzer.cli`` and ``stridefix_lab.cli`` load them by name).
(d) The packages import in one direction: common ← sim, common ← analyzer ← lab, sim ← lab. The
    product (common, sim, analyzer) never imports the lab, the simulator and the analyzer never
    import each other, and the common package imports none of them.
"""

from __future__ import annotations

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]
ROOTS = {
    "stridefix_common": REPO / "common" / "stridefix_common",
    "stridefix_sim": REPO / "hil-sim" / "stridefix_sim",
    "stridefix_analyzer": REPO / "analyzer" / "stridefix_analyzer",
    "stridefix_lab": REPO / "lab" / "stridefix_lab",
}
#: package → the packages it may import (besides itself)
MAY_IMPORT = {
    "stridefix_common": set(),
    "stridefix_sim": {"stridefix_common"},
    "stridefix_analyzer": {"stridefix_common"},
    "stridefix_lab": {"stridefix_common", "stridefix_analyzer", "stridefix_sim"},
}
MAX_LINES = 500
TOP_CLIS = {"stridefix_analyzer.cli", "stridefix_lab.cli"}


def _modules() -> dict[str, Path]:
    """Module name → source file, for every module of the two packages."""
    mods = {}
    for pkg, root in ROOTS.items():
        for path in sorted(root.rglob("*.py")):
            parts = list(path.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            mods[".".join([pkg, *parts])] = path
    return mods


MODULES = _modules()


def _is_type_checking(node: ast.If) -> bool:
    t = node.test
    return (isinstance(t, ast.Name) and t.id == "TYPE_CHECKING") or (
        isinstance(t, ast.Attribute) and t.attr == "TYPE_CHECKING"
    )


def _imported(module: str, path: Path) -> set[str]:
    """The package modules ``module`` imports anywhere (module level or inside functions)."""
    is_pkg = path.name == "__init__.py"
    base = module.split(".") if is_pkg else module.split(".")[:-1]
    found: set[str] = set()

    def resolve(name: str, names: list[str]) -> None:
        # `from a.b import c`: c may be a module (a.b.c) or a name in a.b
        for cand in [f"{name}.{n}" for n in names] + [name]:
            if cand in MODULES:
                found.add(cand)
        # a dotted import also imports its parent packages; only modules with code matter here

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _is_type_checking(child):
                for other in child.orelse:
                    visit(other)
                continue
            if isinstance(child, ast.Import):
                for alias in child.names:
                    if alias.name in MODULES:
                        found.add(alias.name)
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    anchor = base[: len(base) - child.level + 1]
                    name = ".".join(anchor + ([child.module] if child.module else []))
                else:
                    name = child.module or ""
                resolve(name, [a.name for a in child.names])
            visit(child)

    visit(ast.parse(path.read_text(encoding="utf-8"), filename=str(path)))
    found.discard(module)
    return found


GRAPH = {m: _imported(m, p) for m, p in MODULES.items()}


def _cycles(graph: dict[str, set[str]]) -> list[tuple[str, ...]]:
    """Strongly connected components with more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[tuple[str, ...]] = []

    def strong(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(tuple(sorted(comp)))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    return out


def test_the_graph_sees_function_level_imports():
    # the parser must see a lazy import: crowd.cli imports experiment at module level, and the top
    # CLI's sub-commands are loaded by name (no import edge)
    assert "stridefix_analyzer.scoring.analyze" in GRAPH["stridefix_lab.bench.sil_pdr"]
    assert "stridefix_analyzer.io.tum" in GRAPH["stridefix_analyzer.scoring.analyze"]  # inside run()
    assert "stridefix_analyzer.scoring.metrics" not in GRAPH["stridefix_analyzer.io.tum"]  # TYPE_CHECKING


def test_no_import_cycles():
    assert _cycles(GRAPH) == []


def test_no_module_over_max_lines():
    long = {m for m, p in MODULES.items() if len(p.read_text(encoding="utf-8").splitlines()) > MAX_LINES}
    assert sorted(long) == []


def test_no_firmware_source_over_max_lines():
    firmware = REPO / "firmware"
    long = [
        str(p.relative_to(REPO))
        for p in sorted(firmware.rglob("*.[ch]"))
        if len(p.read_text(encoding="utf-8").splitlines()) > MAX_LINES
    ]
    assert long == []


def test_cli_modules_are_imported_by_nobody():
    bad = {(m, dep) for m, deps in GRAPH.items() for dep in deps if dep in TOP_CLIS or dep.endswith(".cli")}
    assert sorted(bad) == []


def test_packages_import_in_one_direction():
    wrong = sorted(
        (m, dep)
        for m, deps in GRAPH.items()
        for dep in deps
        if dep.split(".")[0] != m.split(".")[0] and dep.split(".")[0] not in MAY_IMPORT[m.split(".")[0]]
    )
    assert wrong == []


def test_the_direction_check_sees_every_package():
    # each package's modules are in the graph, and the lab does import the product
    assert {m.split(".")[0] for m in MODULES} == set(ROOTS)
    assert any(d.startswith("stridefix_analyzer.") for d in GRAPH["stridefix_lab.bench.sil_pdr"])


def test_the_product_holds_no_benchmark():
    # the lab's packages have no namesake left in the product
    assert not any(
        m.startswith(("stridefix_analyzer.bench", "stridefix_analyzer.realbench")) for m in MODULES
    )


# The analyzer's packages in data-flow order (docs/ARCHITECTURE.md): a module imports only from its own
# package or from one above it in this list.
LAYERS = (
    "console",
    "helptext",
    "schemes",
    "firmware",
    "spy",
    "parallel",
    "io",
    "frames",
    "datasets",
    "radiomap",
    "scoring",
    "export",
    "live",
    "crowd",
    "cliapp",
    "cli",
)


def test_analyzer_imports_go_down_the_layers():
    def layer(module: str) -> str | None:
        parts = module.split(".")
        return parts[1] if parts[0] == "stridefix_analyzer" and len(parts) > 1 else None

    unlisted = {layer(m) for m in MODULES} - set(LAYERS) - {None, "__init__"}
    assert unlisted == set(), "a new analyzer package needs its place in LAYERS (and in ARCHITECTURE.md)"
    upward = sorted(
        (m, dep)
        for m, deps in GRAPH.items()
        for dep in deps
        if layer(m) in LAYERS and layer(dep) in LAYERS and LAYERS.index(layer(dep)) > LAYERS.index(layer(m))
    )
    assert upward == []
