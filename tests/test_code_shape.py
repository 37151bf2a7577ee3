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
    "envs": ("roto.rl", "roto.eval", "roto.sweep", "roto.olympiad"),
    "rl": ("roto.eval", "roto.sweep", "roto.olympiad"),
}
"""Packages and what they must never import: data flows up, from the envs to the learner to what
evaluates, sweeps and tabulates it."""


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
        for path in sorted((ROOT / package).rglob("*.py")):
            wrong += [
                f"{path.relative_to(ROOT)} imports {m}" for m in imported_modules(path) if m.startswith(forbidden)
            ]
    assert not wrong, wrong
