"""The project's import graph and definition sizes, read from the source (nothing is imported):
what ``tests/test_layering.py`` checks and ``docs/architecture.md``'s picture is drawn from."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("engine", "app", "facetraj", "benchmarks")


def module_name(path: Path) -> str:
    """``engine/method/pipeline.py`` -> ``facetraj_engine.method.pipeline`` (a package: its ``__init__``)."""
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def source_files(packages: tuple[str, ...] = PACKAGES) -> Iterator[Path]:
    for package in packages:
        yield from sorted((ROOT / package).rglob("*.py"))


@dataclass(frozen=True)
class Import:
    importer: str      # module name
    target: str        # the imported module (or package), absolute
    line: int
    top_level: bool    # at module level (not inside a function)


def _resolve(importer: str, is_package: bool, level: int, module: str | None) -> str:
    base = importer.split(".") if is_package else importer.split(".")[:-1]
    if level > 1:
        base = base[:len(base) - (level - 1)]
    return ".".join(base + ([module] if module else []))


def imports_of(path: Path, modules: set[str]) -> list[Import]:
    """Every import in ``path`` of a project module, resolved to the module it loads (``from
    package import name`` counts as the submodule when ``name`` is one)."""
    name = module_name(path)
    tree = ast.parse(path.read_text(encoding="utf-8"))
    top = {id(n) for n in tree.body}
    for n in tree.body:       # imports under `if TYPE_CHECKING:` and `try:` count as top level
        if isinstance(n, (ast.If, ast.Try)):
            top |= {id(m) for m in ast.walk(n)}
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = (_resolve(name, path.name == "__init__.py", node.level, node.module)
                    if node.level else node.module or "")
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base
                       for a in node.names]
        else:
            continue
        for t in dict.fromkeys(targets):
            while t and t not in modules and "." in t:
                t = t.rsplit(".", 1)[0]
            if t in modules and t != name:
                out.append(Import(name, t, node.lineno, id(node) in top))
    return out


def import_graph(packages: tuple[str, ...] = PACKAGES) -> list[Import]:
    files = list(source_files(packages))
    modules = {module_name(p) for p in files}
    return [imp for p in files for imp in imports_of(p, modules)]


def circles(edges: list[Import]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    graph: dict[str, set[str]] = {}
    for e in edges:
        graph.setdefault(e.importer, set()).add(e.target)
        graph.setdefault(e.target, set())
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


@dataclass(frozen=True)
class Definition:
    path: str
    name: str
    kind: str          # "function" or "class"
    lines: int


def definitions(packages: tuple[str, ...] = (*PACKAGES, "tests")) -> Iterator[Definition]:
    """Every function and class of the project's source and tests, with its length in lines."""
    for path in source_files(packages):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                kind = "class" if isinstance(node, ast.ClassDef) else "function"
                yield Definition(str(path.relative_to(ROOT)), node.name, kind,
                                 node.end_lineno - node.lineno + 1)


# --------------------------------------------------------------------------- the picture
#: Where docs/architecture.md keeps the generated picture.
PICTURE_START = "<!-- picture: generated by `python tests/structure.py`; do not edit by hand -->"
PICTURE_END = "<!-- end of picture -->"
SHARED_NAMES = ("config", "data", "errors", "fanout", "progress", "threads")


def box_of(module: str) -> str:
    """The box of the picture a module is drawn in: an engine stage, the engine's shared
    modules, or a top-level package."""
    parts = module.split(".")
    if parts[0] != "engine":
        return parts[0]
    if len(parts) == 1 or parts[1] in SHARED_NAMES:
        return "engine.shared"
    return f"engine.{parts[1]}"


def mermaid(edges: list[Import] | None = None) -> str:
    """A Mermaid flowchart of the boxes (with their module counts) and the imports between
    them: arrows point from importer to imported; the arrows into the engine's shared modules are
    left out. It changes when the structure does, not with every line."""
    edges = import_graph() if edges is None else edges
    files: dict[str, int] = {}
    for path in source_files():
        box = box_of(module_name(path))
        files[box] = files.get(box, 0) + 1
    arrows = {(box_of(e.importer), box_of(e.target)) for e in edges}
    arrows = {(a, b) for a, b in arrows if a != b and b != "engine.shared"}
    ids = {box: box.replace(".", "_") for box in files}
    lines = ["```mermaid", "flowchart TD"]
    lines += [f'  {ids[box]}["{box}<br/>{files[box]} modules"]' for box in sorted(files, key=_box_order)]
    lines += [f"  {ids[a]} --> {ids[b]}"
              for a, b in sorted(arrows, key=lambda ab: (_box_order(ab[0]), _box_order(ab[1])))]
    lines.append("```")
    return "\n".join(lines)


def _box_order(box: str) -> tuple[int, str]:
    order = ["benchmarks", "facetraj", "app", "facetraj_engine.corpusgen", "facetraj_engine.report", "facetraj_engine.analysis",
             "facetraj_engine.evaluation", "facetraj_engine.streaming", "facetraj_engine.method", "facetraj_engine.io", "facetraj_engine.labels",
             "engine.shared"]
    return (order.index(box) if box in order else len(order), box)


def picture_in(text: str) -> str:
    """The generated picture block of a page (between PICTURE_START and PICTURE_END)."""
    start, end = text.index(PICTURE_START) + len(PICTURE_START), text.index(PICTURE_END)
    return text[start:end].strip()


if __name__ == "__main__":    # rewrite the picture of docs/architecture.md
    page = ROOT / "docs" / "architecture.md"
    text = page.read_text(encoding="utf-8")
    start, end = text.index(PICTURE_START) + len(PICTURE_START), text.index(PICTURE_END)
    new = f"{text[:start]}\n{mermaid()}\n{text[end:]}"
    page.write_text(new, encoding="utf-8")
    print(f"{page}: picture {'rewritten' if new != text else 'unchanged'}")
