"""The code-shape rule: no file under roto/ over 400 lines, no function under roto/ or benchmarks/ over 60."""

import ast
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
MAX_FILE_LINES = 400
MAX_FUNCTION_LINES = 60


def _python_files(*folders: str) -> list[pathlib.Path]:
    return sorted(path for folder in folders for path in (ROOT / folder).rglob("*.py"))


def test_the_code_is_where_the_rule_expects_it():
    assert _python_files("roto") and _python_files("benchmarks"), f"no Python files found under {ROOT}"


def test_no_file_under_roto_is_over_400_lines():
    too_long = []
    for path in _python_files("roto"):
        lines = len(path.read_text().splitlines())
        if lines > MAX_FILE_LINES:
            too_long.append(f"{path.relative_to(ROOT)}:1 has {lines} lines")
    assert not too_long, f"files over {MAX_FILE_LINES} lines:\n" + "\n".join(too_long)


def test_no_function_is_over_60_lines():
    too_long = []
    for path in _python_files("roto", "benchmarks"):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    too_long.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name} is {lines} lines")
    assert not too_long, f"functions over {MAX_FUNCTION_LINES} lines:\n" + "\n".join(too_long)


LAYERS = {
    "envs": ("roto.rl", "roto.eval", "roto.sweep", "roto.olympiad", "roto.registry", "roto.wrappers"),
    "rl": ("roto.eval", "roto.sweep", "roto.olympiad"),
    "jobs": ("roto.envs", "roto.eval", "roto.sweep", "roto.olympiad"),
}
"""Packages and what they must never import: data flows up, from the envs to the learner to what
evaluates, sweeps and tabulates it; the registry (``roto.make``) and the adapters for other
libraries stand on the envs."""


def imported_modules(path: pathlib.Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
        elif isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
    return names


def test_lower_layers_never_import_higher_ones():
    wrong = []
    for package, forbidden in LAYERS.items():
        paths = sorted((ROOT / "roto" / package).rglob("*.py"))
        assert paths, f"no Python files under roto/{package}"
        for path in paths:
            wrong += [
                f"{path.relative_to(ROOT)} imports {m}" for m in imported_modules(path) if m.startswith(forbidden)
            ]
    assert not wrong, wrong


def private_reads(path: pathlib.Path) -> list[str]:
    """``obj._name`` reads of another object's private attribute in ``path`` (``self._x`` and
    ``cls._x`` are the object's own; dunders are Python's)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        private = isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__")
        if private and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls")):
            found.append(f"{path.relative_to(ROOT)}:{node.lineno} reads .{node.attr}")
    return found


def test_training_aids_know_their_env_only_through_the_protocol():
    """An aid is built from an ``AidHost`` and sees steps through a ``StepContext``: it never imports
    the env nor reads another object's private state (roto/envs/aids/protocol.py)."""
    paths = sorted((ROOT / "roto" / "envs" / "aids").rglob("*.py"))
    assert len(paths) >= 5
    wrong = [f"{p.relative_to(ROOT)} imports {m}" for p in paths for m in imported_modules(p) if "roto_env" in m]
    wrong += [read for path in paths for read in private_reads(path)]
    assert not wrong, wrong


def module_name(path: pathlib.Path) -> str:
    return ".".join(path.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")


def import_circles(package: str) -> list[list[str]]:
    """The circles in the import graph of ``package``'s modules (imports under ``TYPE_CHECKING``
    count: they tie the files together as much)."""
    paths = sorted((ROOT / package.replace(".", "/")).rglob("*.py"))
    modules = {module_name(path): path for path in paths}
    edges = {name: {m for m in imported_modules(path) if m in modules and m != name} for name, path in modules.items()}
    circles, done = [], set()

    def visit(name: str, trail: list[str]) -> None:
        if name in trail:
            circles.append([*trail[trail.index(name) :], name])
            return
        if name in done:
            return
        for other in sorted(edges[name]):
            visit(other, [*trail, name])
        done.add(name)

    for name in sorted(modules):
        visit(name, [])
    return circles


def test_the_envs_have_no_import_circle_and_no_private_reads_across_files():
    """RotoEnv is composed of parts with public interfaces: no module of roto/envs imports one that
    imports it back, and none reads another object's private state."""
    assert len(list((ROOT / "roto" / "envs").rglob("*.py"))) > 20
    assert import_circles("roto.envs") == []
    reads = [read for path in sorted((ROOT / "roto" / "envs").rglob("*.py")) for read in private_reads(path)]
    assert reads == []
