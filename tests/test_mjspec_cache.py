"""MuJoCo's parse of a generated MJCF made once per text (robotwright._mjspec_cache): each
caller gets a spec of its own, what it compiles to is what a new parse compiles to, and a
text is kept only once it has compiled as it is (a copy of a spec drops what refers to
something missing, so a copy of a parse MuJoCo refuses would compile)."""

from __future__ import annotations

from collections import OrderedDict

import mujoco
import numpy as np
import pytest

import robotwright._mjspec_cache as cache

_XML = """<mujoco model="{name}"><worldbody><body name="arm" pos="0 0 1">
<joint name="hinge" axis="0 1 0"/><geom name="rod" type="capsule" fromto="0 0 0 0.3 0 0"
size="0.02"/><body name="tip" pos="0.3 0 0"><joint axis="1 0 0"/><geom size="0.05"/></body>
</body></worldbody>{more}</mujoco>"""


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


def test_a_text_that_compiled_is_parsed_once_and_each_copy_compiles_as_a_new_parse(
    parses,
) -> None:
    xml = _XML.format(name="arm", more="")
    first = cache.compiled(xml)
    mine = cache.parsed_spec(xml)
    mine.geom("rod").size = [0.05, 0, 0]  # a caller's change stays in its own spec
    again = cache.parsed_spec(xml).compile()
    widened = cache.compiled(xml, lambda spec: setattr(spec.geom("rod"), "size", [0.04, 0, 0]))
    assert parses == [xml]
    fresh = mujoco.MjSpec.from_string(xml).compile()
    for name, values in _arrays(fresh).items():
        np.testing.assert_array_equal(getattr(first, name), values, err_msg=name)
        np.testing.assert_array_equal(getattr(again, name), values, err_msg=name)
    assert mine.compile().geom_size[0, 0] == 0.05 and widened.geom_size[0, 0] == 0.04


def test_a_model_mujoco_refuses_is_refused_each_time_and_never_kept(parses) -> None:
    """A sensor of a joint the model lacks: a copy of the parse compiles (MuJoCo drops
    the sensor), the parse does not; so nothing is kept, and each call parses anew."""
    bad = _XML.format(name="arm", more="<sensor><jointpos joint='missing'/></sensor>")
    assert mujoco.MjSpec.from_string(bad).copy().compile().nsensor == 0  # the trap
    for _ in range(2):
        with pytest.raises(ValueError, match="missing"):
            cache.compiled(bad)
        with pytest.raises(ValueError, match="missing"):
            cache.parsed_spec(bad).compile()
    assert not cache._parsed and parses.count(bad) == 5  # the trap's own parse, 4 of ours


def test_a_text_is_kept_only_compiled_as_it_is(parses) -> None:
    """parsed_spec keeps nothing; compiled with a change first keeps nothing either."""
    xml = _XML.format(name="arm", more="")
    cache.parsed_spec(xml)
    cache.compiled(xml, lambda spec: None)
    assert not cache._parsed and parses == [xml, xml]


def test_only_the_last_texts_are_kept_and_forget_drops_them(parses) -> None:
    texts = [_XML.format(name=f"arm{i}", more="") for i in range(cache._KEPT + 1)]
    for xml in texts:
        cache.compiled(xml)
    cache.compiled(texts[-1])  # kept
    cache.compiled(texts[0])  # the oldest, dropped: parsed again
    assert parses == [*texts, texts[0]]
    cache.forget()
    cache.parsed_spec(texts[0])
    assert parses == [*texts, texts[0], texts[0]]
