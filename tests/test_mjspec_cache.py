"""MuJoCo's parse of a generated MJCF made once per text (robotwright._mjspec_cache): each
caller gets a copy of its own, the model compiled from it is the one a new parse gives,
and what MuJoCo refuses is never kept."""

from __future__ import annotations

from collections import OrderedDict

import mujoco
import numpy as np
import pytest

import robotwright._mjspec_cache as cache

_XML = """<mujoco model="{name}"><worldbody><body name="arm" pos="0 0 1">
<joint name="hinge" axis="0 1 0"/><geom name="rod" type="capsule" fromto="0 0 0 0.3 0 0"
size="0.02"/><body name="tip" pos="0.3 0 0"><joint axis="1 0 0"/><geom size="0.05"/></body>
</body></worldbody></mujoco>"""


@pytest.fixture
def parses(monkeypatch) -> list[str]:
    """The texts MuJoCo is asked to parse, with nothing kept from before."""
    monkeypatch.setattr(cache, "_parsed", OrderedDict())
    asked: list[str] = []
    real = mujoco.MjSpec.from_string

    def from_string(xml, *args, **kwargs):
        asked.append(xml)
        return real(xml, *args, **kwargs)

    monkeypatch.setattr(mujoco.MjSpec, "from_string", staticmethod(from_string))
    return asked


def _arrays(model: mujoco.MjModel) -> dict[str, np.ndarray]:
    return {
        n: getattr(model, n)
        for n in dir(model)
        if not n.startswith("_") and isinstance(getattr(model, n, None), np.ndarray)
    }


def test_a_text_is_parsed_once_and_each_copy_compiles_as_a_new_parse(parses) -> None:
    xml = _XML.format(name="arm")
    first = cache.parsed_spec(xml)
    first.geom("rod").size = [0.05, 0, 0]  # a caller's change stays in its own copy
    second = cache.parsed_spec(xml)
    assert parses == [xml]
    fresh = mujoco.MjSpec.from_string(xml).compile()
    ours = second.compile()
    assert ours.geom_size[0, 0] == 0.02 and first.compile().geom_size[0, 0] == 0.05
    for name, values in _arrays(fresh).items():
        np.testing.assert_array_equal(getattr(ours, name), values, err_msg=name)


def test_only_the_last_texts_are_kept_and_forget_drops_them(parses) -> None:
    texts = [_XML.format(name=f"arm{i}") for i in range(cache._KEPT + 1)]
    for xml in texts:
        cache.parsed_spec(xml)
    cache.parsed_spec(texts[-1])  # kept
    cache.parsed_spec(texts[0])  # the oldest, dropped: parsed again
    assert parses == [*texts, texts[0]]
    cache.forget()
    cache.parsed_spec(texts[0])
    assert parses == [*texts, texts[0], texts[0]]


def test_a_text_mujoco_refuses_is_refused_each_time_and_not_kept(parses) -> None:
    bad = "<mujoco><worldbody><geom type='nonsense'/></worldbody></mujoco>"
    for _ in range(2):
        with pytest.raises(ValueError):
            cache.parsed_spec(bad)
    assert parses == [bad, bad] and not cache._parsed
