"""The limb picture names joint kinds correctly and keeps labels apart."""

from __future__ import annotations

import matplotlib.image as mpimg
import numpy as np

from robotwright.grammar import default_grammar, demo_limb_design
from robotwright.grammar.build import build
from robotwright.grammar.draw import _joint_kinds, _merge_labels, draw_limb, joint_summary


def test_title_names_joint_kinds_and_universal_as_two_dof() -> None:
    # Demo design 3: a prismatic, a revolute and a universal connector.
    limb = build(default_grammar(), demo_limb_design(3))
    assert joint_summary(limb) == "4 DoF: prismatic, revolute, universal (2 DoF)"
    kinds = _joint_kinds(limb)
    assert sorted(kinds.values()) == ["prismatic", "revolute", "universal 1/2", "universal 2/2"]
    slides = {j.name for j in limb.joints if j.type == "slide"}
    assert {n for n, k in kinds.items() if k == "prismatic"} == slides


def test_close_labels_are_merged() -> None:
    merged = _merge_labels(
        [np.zeros(3), np.array([0.01, 0, 0]), np.array([1.0, 0, 0])], ["a", "b", "c"], 0.05
    )
    assert [text for _, text in merged] == ["a, b", "c"]


def test_draw_limb_writes_png(tmp_path) -> None:
    limb = build(default_grammar(), demo_limb_design(3))
    out = draw_limb(limb, tmp_path / "limb.png", q=np.full(limb.dof, 0.1))
    assert mpimg.imread(out).shape[:2] == (600, 600)
