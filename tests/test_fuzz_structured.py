"""Structure-aware fuzzing of the model readers (hypothesis): a built-in robot's YAML or URDF with one to three
random edits — a value replaced by a hostile one (NaN, ±inf, 1e308, −1, 0, a string, a list, null), a key
deleted, a body duplicated — must load or be refused with `ModelError`/`InputError`, never another exception or
a crash. Byte-level fuzzing (fuzz/readers.py) rarely gets past the parser's syntax checks into the model
checks; these edits start from valid files, so every one reaches them."""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET

import numpy as np
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import freefloat as ff

EXPECTED = (ff.ModelError, ff.InputError, ff.NumericalError)
MODELS = ("naveen_dual_arm", "zhang2020_2d_medium", "zhang2020_3d", "valverde_ch7_two_arm")
HOSTILE = (float("nan"), float("inf"), -float("inf"), 1e308, -1.0, 0.0, 1e-300, "ten", [], [1.0], {}, None, True)
SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _leaves(node, path=()):
    """Every (path, value) in a nested dict/list, containers included (so a whole block can be replaced)."""
    yield path, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _leaves(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _leaves(v, (*path, i))


def _parent(doc, path):
    for k in path[:-1]:
        doc = doc[k]
    return doc


def _edit(doc, choice: int, kind: int, value):
    paths = [p for p, _ in _leaves(doc) if p]
    path = paths[choice % len(paths)]
    parent = _parent(doc, path)
    if kind == 0:
        parent[path[-1]] = value
    elif kind == 1:
        del parent[path[-1]]
    elif isinstance(parent, list):  # duplicate an element of a list (a body, an axis entry, ...)
        parent.append(copy.deepcopy(parent[path[-1]]))
    else:
        parent[path[-1]] = value
    return doc


edits = st.lists(st.tuples(st.integers(0, 10_000), st.integers(0, 2), st.sampled_from(HOSTILE)), min_size=1, max_size=3)


@SETTINGS
@given(st.sampled_from(MODELS), edits)
def test_edited_yaml_model_loads_or_is_refused_clearly(name, changes):
    doc = yaml.safe_load(ff.models.source(name))
    for choice, kind, value in changes:
        doc = _edit(doc, choice, kind, value)
    text = yaml.safe_dump(doc)
    try:
        m = ff.Model.from_yaml_string(text)
    except EXPECTED as e:
        assert str(e), "an error must say what is wrong"
        return
    # accepted: then it must be a working model
    q = m.neutral()
    assert np.all(np.isfinite(ff.crba(m, q)))


def _urdf_elements(root):
    return [(el, a) for el in root.iter() for a in el.attrib]


@SETTINGS
@given(st.sampled_from(("naveen_dual_arm", "zhang2020_3d")), edits)
def test_edited_urdf_model_loads_or_is_refused_clearly(name, changes):
    root = ET.fromstring(ff.models.load(name).to_urdf())
    for choice, kind, value in changes:
        targets = _urdf_elements(root)
        el, attr = targets[choice % len(targets)]
        if kind == 1:
            del el.attrib[attr]
        else:
            el.set(attr, " ".join(str(value) for _ in range(len(el.get(attr, "").split()) or 1)))
    text = ET.tostring(root, encoding="unicode")
    try:
        m = ff.Model.from_urdf_string(text)
    except EXPECTED as e:
        assert str(e)
        return
    assert np.all(np.isfinite(ff.crba(m, m.neutral())))
