"""Write `python/freefloat/_core.pyi`, the type stub of the compiled engine module, from the built module itself.

    python tools/stubgen.py            # rewrite the stub from the installed freefloat._core
    python tools/stubgen.py --check    # exit 1 if the stub on disk differs from what would be written

Parameter names, defaults and docstrings come from the compiled module (`__text_signature__`, `__doc__`), so the
stub cannot drift from the bindings; tests/test_packaging.py checks it with --check semantics. Types follow the
bindings' conventions: arrays in are anything numpy converts (`ArrayLike`), arrays out are `numpy.ndarray`.
"""

from __future__ import annotations

import inspect
import sys
from pathlib import Path

STUB = Path(__file__).resolve().parents[1] / "python" / "freefloat" / "_core.pyi"

# Parameter name -> annotation. Anything not listed is an array-like input (the common case in this module).
PARAM_TYPES = {
    "model": "Model",
    "name": "str",
    "reference": "str",
    "method": "str",
    "hold": "str",
    "formulation": "str",
    "coupling": "str",
    "text": "str",
    "source": "str",
    "base": "str",
    "t_final": "float",
    "dt": "float",
    "rtol": "float",
    "atol": "float",
    "max_step": "float | None",
    "controller_period": "float | None",
    "half_angle": "float",
    "max_angle": "float",
    "forgetting": "float",
    "weight": "float",
    "delta": "float",
    "theta": "float",
    "d": "float",
    "a": "ArrayLike",
    "alpha": "float",
    "record_every": "int",
    "max_steps": "int",
    "threads": "int",
    "stride": "int",
    "offset": "int",
    "n_signal": "int",
    "step": "float",
    "allow_nonphysical": "bool",
    "classical": "bool",
    "controller": "Callable[..., ArrayLike] | None",
    "prescription": "Callable[..., Any] | None",
    "progress": "Callable[[float], Any] | None",
    "torques": "ArrayLike | Callable[..., ArrayLike] | None",
    "other": "DualQuaternion",
    "x": "Any",
    "g": "ArrayLike",
    "params": "ArrayLike",
}

# Return annotations where the binding's result type is fixed; everything else is `Any`.
RETURNS = {
    **{
        f: "np.ndarray"
        for f in (
            "aba",
            "rnea",
            "crba",
            "center_of_mass",
            "momentum",
            "kinetic_energy",
            "centroidal_momentum_matrix",
            "momentum_regressor",
            "dynamics_regressor",
            "frame_jacobian",
            "body_velocities",
            "body_accelerations",
            "forward_kinematics",
            "frame_placement",
            "neutral",
            "parameters",
            "left_matrix",
            "right_matrix",
            "rotation_matrix",
            "translation",
        )
    },
    "generalized_jacobian": "tuple[np.ndarray, np.ndarray]",
    "hybrid_dynamics": "tuple[np.ndarray, np.ndarray]",
    "dq_dynamics": "tuple[np.ndarray, np.ndarray]",
    "builtin": "Model",
    "from_urdf_string": "Model",
    "from_yaml_string": "Model",
    "with_gravity": "Model",
    "with_parameters": "Model",
    "builtin_names": "list[str]",
    "builtin_source": "str",
    "to_urdf_string": "str",
    "body_names": "list[str]",
    "joint_names": "list[str]",
    "frame_names": "list[str]",
    "joint_types": "list[str]",
    "name": "str",
    "nq": "int",
    "nv": "int",
    "nbodies": "int",
    "total_mass": "float",
    "conj": "DualQuaternion",
    "inverse": "DualQuaternion",
    "normalized": "DualQuaternion",
    "properized": "DualQuaternion",
    "swap": "DualQuaternion",
    "log": "DualQuaternion",
    "cross": "DualQuaternion",
    "dot": "DualQuaternion",
    "circle": "float",
    "is_unit": "bool",
    "unit_defect": "float",
    "tolist": "list[float]",
    "to_pose": "tuple[np.ndarray, np.ndarray]",
}


def _ret(name: str) -> str:
    return RETURNS.get(name, "Any")


def _annot(name: str, default: str | None) -> str:
    t = PARAM_TYPES.get(name, "ArrayLike")
    if default == "None" and "None" not in t:
        t += " | None"
    return t


def _method_params(sig: str):
    # "($self, other)" or "(name)" for static methods: parse with inspect on a dummy function.
    inner = sig.strip()[1:-1].replace("$self", "self").replace("$cls", "cls")
    ns: dict = {}
    exec(f"def _f({inner}): pass", {}, ns)
    for p in inspect.signature(ns["_f"]).parameters.values():
        if p.name in ("self", "cls"):
            yield p.name
        else:
            yield _fmt(p)


def _fmt(p: inspect.Parameter) -> str:
    if p.kind is p.VAR_POSITIONAL:
        return f"*{p.name}: Any"
    if p.kind is p.VAR_KEYWORD:
        return f"**{p.name}: Any"
    default = None if p.default is inspect.Parameter.empty else repr(p.default)
    s = f"{p.name}: {_annot(p.name, default)}"
    return s if default is None else f"{s} = {default}"


def _func_params(obj) -> str:
    sig = getattr(obj, "__text_signature__", None)
    if sig is None:
        return "*args: Any, **kwargs: Any"
    return ", ".join(_fmt(p) for p in inspect.signature(obj).parameters.values())


def _doc(obj, indent: str) -> str:
    doc = inspect.getdoc(obj)
    if not doc:
        return f"{indent}...\n"
    doc = doc.replace('"""', "'''").replace("\\", "\\\\")
    return f'{indent}"""{doc}"""\n' if "\n" not in doc else f'{indent}"""{doc}\n{indent}"""\n'


def render() -> str:
    import freefloat._core as core

    out = [
        '"""Type stub of freefloat._core, the compiled Rust engine (written by tools/stubgen.py: do not edit)."""\n\n',
        "from typing import Any, Callable\n\nimport numpy as np\nfrom numpy.typing import ArrayLike\n\n",
    ]
    for name in sorted(dir(core)):
        if name.startswith("__"):
            continue
        obj = getattr(core, name)
        if inspect.isclass(obj) and issubclass(obj, BaseException):
            base = obj.__mro__[1].__name__
            out.append(f"class {name}({base}):\n{_doc(obj, '    ')}\n")
        elif inspect.isclass(obj):
            out.append(f"class {name}:\n{_doc(obj, '    ')}")
            sig = getattr(obj, "__text_signature__", None)
            if sig is not None:
                ps = ", ".join(["self", *(_fmt(p) for p in inspect.signature(obj).parameters.values())])
                out.append(f"    def __init__({ps}) -> None: ...\n")
            for mname in sorted(vars(obj)):
                if mname.startswith("__"):
                    continue
                raw = vars(obj)[mname]
                attr = getattr(obj, mname)
                if type(raw).__name__ == "getset_descriptor":
                    out.append(f"    @property\n    def {mname}(self) -> {_ret(mname)}:\n{_doc(attr, '        ')}")
                elif type(raw).__name__ in ("staticmethod", "builtin_function_or_method") or isinstance(
                    raw, staticmethod
                ):
                    ps = ", ".join(_method_params(attr.__text_signature__ or "()"))
                    out.append(f"    @staticmethod\n    def {mname}({ps}) -> {_ret(mname)}:\n{_doc(attr, '        ')}")
                elif type(raw).__name__ == "classmethod_descriptor":
                    sig = (attr.__text_signature__ or "($cls)").replace("($cls, ", "(").replace("($cls)", "()")
                    ps = ", ".join(["cls", *_method_params(sig)])
                    out.append(f"    @classmethod\n    def {mname}({ps}) -> Any:\n{_doc(attr, '        ')}")
                else:
                    ps = ", ".join(_method_params(attr.__text_signature__ or "($self)"))
                    out.append(f"    def {mname}({ps}) -> {_ret(mname)}:\n{_doc(attr, '        ')}")
            out.append("\n")
        elif callable(obj):
            out.append(f"def {name}({_func_params(obj)}) -> {_ret(name)}:\n{_doc(obj, '    ')}\n")
        else:
            out.append(f"{name}: {type(obj).__name__}\n\n")
    return "".join(out).rstrip() + "\n"


def main() -> int:
    text = render()
    if "--check" in sys.argv:
        if not STUB.exists() or STUB.read_text(encoding="utf-8") != text:
            print(f"{STUB} is out of date: run `python tools/stubgen.py`")
            return 1
        return 0
    STUB.write_text(text, encoding="utf-8")
    print(f"wrote {STUB}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
