"""The packages' import graph, read statically: no cycle among the project's modules (imports inside
functions included, so none is held apart by a late import), and no module reaching for another
module's private (underscore) name."""

from __future__ import annotations

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGES = ("splid_jax", "envs")


def module_name(path: Path) -> str:
    parts = path.relative_to(REPO).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def project_modules() -> dict[str, ast.Module]:
    return {
        module_name(p): ast.parse(p.read_text(), str(p)) for package in PACKAGES for p in (REPO / package).rglob("*.py")
    }


def imports(tree: ast.Module, modules: dict) -> list[tuple[str, str | None]]:
    """(module, name) for every import in ``tree`` of a project module; name None for ``import m``."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(a.name, None) for a in node.names if a.name in modules]
        elif isinstance(node, ast.ImportFrom) and node.module in modules:
            for a in node.names:
                sub = f"{node.module}.{a.name}"
                found.append((sub, None) if sub in modules else (node.module, a.name))
    return found


def graph() -> dict[str, set[str]]:
    modules = project_modules()
    return {name: {m for m, _ in imports(tree, modules)} for name, tree in modules.items()}


def cycle(edges: dict[str, set[str]]) -> list[str] | None:
    """A cycle of ``edges`` as the modules along it, or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        path.append(m)
        for n in sorted(edges.get(m, ())):
            if state.get(n) == 1:
                return path[path.index(n) :] + [n]
            if n not in state and (found := visit(n)):
                return found
        path.pop()
        state[m] = 2
        return None

    for m in sorted(edges):
        if m not in state and (found := visit(m)):
            return found
    return None


def test_the_cycle_finder_finds_a_cycle_and_accepts_a_tree():
    assert cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert cycle({"a": {"b", "c"}, "b": {"c"}, "c": set()}) is None


def test_no_module_imports_itself_back_through_others():
    edges = graph()
    assert {"splid_jax.config", "splid_jax.learners.registry", "envs"} <= set(edges)  # the walk sees the tree
    assert cycle(edges) is None


def private_uses(tree: ast.Module, modules: dict) -> list[str]:
    """``from m import _x`` and ``m._x`` where ``m`` is a project module bound by an import."""
    found = [f"{m}.{n}" for m, n in imports(tree, modules) if n and n.startswith("_") and not n.startswith("__")]
    bound = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            bound.update({(a.asname or a.name): a.name for a in node.names if a.name in modules})
        elif isinstance(node, ast.ImportFrom) and node.module:
            bound.update({(a.asname or a.name): f"{node.module}.{a.name}" for a in node.names
                          if f"{node.module}.{a.name}" in modules})  # fmt: skip
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name)
            and node.value.id in bound
            and node.attr.startswith("_")
            and not node.attr.startswith("__")
        ):
            found.append(f"{bound[node.value.id]}.{node.attr}")
    return found


def test_the_private_name_finder_sees_both_spellings():
    modules = {"pkg.mod": None}
    tree = ast.parse("from pkg.mod import _hidden\nfrom pkg import mod\nmod._inner()\nmod.__name__")
    assert private_uses(tree, modules) == ["pkg.mod._hidden", "pkg.mod._inner"]


def test_no_module_imports_another_modules_private_name():
    modules = project_modules()
    found = {name: uses for name, tree in modules.items() if (uses := private_uses(tree, modules))}
    assert found == {}


def test_the_tasks_import_nothing_of_the_trainer():
    """``envs`` stands alone: a task is usable without the learners, and the trainer depends on it, not back."""
    modules = project_modules()
    edges = {name: {m for m, _ in imports(tree, modules)} for name, tree in modules.items() if name.startswith("envs")}
    assert {"envs", "envs.fetch.tasks"} <= set(edges)
    assert {name: sorted(m for m in used if m.startswith("splid_jax")) for name, used in edges.items()
            if any(m.startswith("splid_jax") for m in used)} == {}  # fmt: skip


def test_no_task_module_over_400_lines():
    """One module, one job: a task module that grows past 400 lines holds two."""
    lines = {str(p.relative_to(REPO)): len(p.read_text().splitlines()) for p in (REPO / "envs").rglob("*.py")}
    assert len(lines) > 10
    long = {path: n for path, n in lines.items() if n > 400}
    assert long == {}


def top_level_imports(tree: ast.Module) -> set[str]:
    """Modules ``tree`` imports when it is imported (not inside its functions)."""
    found = set()
    for node in tree.body:
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            found |= {node.module} | {f"{node.module}.{a.name}" for a in node.names}
    return found


def test_importing_the_tasks_reaches_no_private_mjx_code():
    """The tasks import on a MuJoCo whose private code moved, and there run stock MJX: only the physics kernels
    (imported when a step uses them) reach into ``mujoco.mjx._src``."""
    modules = project_modules()
    seen, todo = set(), ["envs", "envs.fetch.tasks", "envs.fetch.scripted", "envs.reacher", "envs.sawyer_door"]
    while todo:
        if (name := todo.pop()) in seen or name not in modules:
            continue
        seen.add(name)
        todo += [m for m in top_level_imports(modules[name]) if m in modules]
    assert {"envs.fetch.tasks", "envs.fetch.kernels", "envs.base"} <= seen
    private = {name for name in seen if any(m.startswith("mujoco.mjx._src") for m in top_level_imports(modules[name]))}
    assert private == set()
