"""The installed package is complete: every third-party module it imports is a declared run-time dependency,
its data files are found through importlib.resources, and it is not imported from the source tree."""

from __future__ import annotations

import ast
import re
import sys
from importlib import metadata, resources
from pathlib import Path

import freefloat as ff
from freefloat import data

PKG = Path(ff.__file__).resolve().parent


def _third_party_imports() -> dict[str, str]:
    """Top-level module name -> first file importing it, over every module of the installed package."""
    stdlib = set(sys.stdlib_module_names)
    found: dict[str, str] = {}
    for f in sorted(PKG.rglob("*.py")):
        tree = ast.parse(f.read_text(encoding="utf-8"), filename=str(f))
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for n in names:
                top = n.split(".")[0]
                if top not in stdlib and top != "freefloat":
                    found.setdefault(top, str(f.relative_to(PKG)))
    return found


def _declared(extra: str | None = None) -> set[str]:
    """Distributions in [project.dependencies], or in the optional extra `extra`."""
    reqs = metadata.requires("freefloat") or []
    core = [r for r in reqs if ("extra ==" not in r if extra is None else re.search(rf"extra == .{extra}.", r))]
    return {re.split(r"[\s<>=!~;\[]", r, maxsplit=1)[0].lower().replace("_", "-") for r in core}


def test_every_runtime_import_is_a_declared_dependency():
    dist_of = metadata.packages_distributions()
    # `mujoco` is an optional extra ([mujoco]); only freefloat.io.mujoco imports it, inside functions
    declared = _declared() | _declared("mujoco")
    imports = _third_party_imports()
    assert "numpy" in imports and "yaml" in imports, "the AST walk found nothing: the check would be vacuous"
    missing = {}
    for mod, where in imports.items():
        dists = {d.lower().replace("_", "-") for d in dist_of.get(mod, [mod])}
        if not dists & declared:
            missing[mod] = (where, sorted(dists))
    assert not missing, f"imported but not in [project.dependencies]: {missing}"


def _editable_install() -> bool:
    """Whether freefloat is installed in editable mode (PEP 610 `direct_url.json`)."""
    import json

    try:
        text = metadata.distribution("freefloat").read_text("direct_url.json")
    except metadata.PackageNotFoundError:
        return False
    return bool(text) and bool(json.loads(text).get("dir_info", {}).get("editable"))


def test_package_is_not_imported_from_the_source_tree_by_path():
    # Under a wheel the package lives in site-packages and is found by the import system, never by a sys.path
    # entry that points into the checkout's python/. An editable install (maturin develop / pip install -e) puts
    # exactly that entry on sys.path through its .pth file, by design, so the check only applies to normal installs.
    import pytest

    if _editable_install():
        pytest.skip("editable install: its .pth file puts python/ on sys.path by design")
    assert not any(Path(p).name == "python" and (Path(p) / "freefloat").is_dir() for p in sys.path if p)


def test_shipped_data_is_found_through_importlib_resources():
    assert resources.files("freefloat.data").joinpath("scenarios").is_dir()
    scen = data.names("scenarios")
    assert len(scen) >= 5, scen  # 2D small/medium/large, the velocity sweep, 3D
    assert data.names("trajectories"), "the designed exciting trajectory is missing"
    for name in scen:
        assert data.read_text("scenarios", name).strip(), name
    with data.path("trajectories", data.names("trajectories")[0]) as p:
        assert p.is_file() and p.stat().st_size > 1000


def test_unknown_shipped_file_is_a_clear_error():
    import pytest

    with pytest.raises(ff.InputError, match="no built-in scenario 'nope'.*built-in:"):
        data.read_text("scenarios", "nope")
    with pytest.raises(ff.InputError, match="unknown data kind"):
        data.names("robots")


def test_builtin_models_are_embedded_in_the_engine():
    assert len(ff.models.names()) >= 9
    for n in ff.models.names():
        assert ff.models.load(n).nbodies >= 2, n


def test_type_stub_matches_the_compiled_module():
    """python/freefloat/_core.pyi is generated from the compiled module (tools/stubgen.py); a binding added or
    changed without regenerating it fails here. The installed package carries the stub and py.typed."""
    import importlib.util
    import subprocess

    tool = Path(__file__).resolve().parents[1] / "tools" / "stubgen.py"
    r = subprocess.run([sys.executable, str(tool), "--check"], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert (PKG / "_core.pyi").is_file() and (PKG / "py.typed").is_file()
    spec = importlib.util.find_spec("freefloat._core")
    assert spec is not None and spec.origin and Path(spec.origin).parent == PKG


def test_load_trajectory_takes_a_file_or_a_built_in_name():
    import pytest

    from freefloat.io.trajectory_files import load_trajectory

    with data.path("trajectories", "naveen_exciting_trajectory") as p:
        by_file, joints_f = load_trajectory(p)
    by_name, joints_n = load_trajectory("naveen_exciting_trajectory")
    assert joints_n == joints_f and by_name.n_intervals == by_file.n_intervals == 63
    with pytest.raises(ff.InputError, match="neither a file nor a built-in trajectory.*naveen_exciting_trajectory"):
        load_trajectory("no_such_trajectory")
