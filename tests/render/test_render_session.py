"""An animation's frames share one render session: one OpenGL context however many
frames (made once, or tried once when no platform starts), and the frames are the
pictures drawn one by one."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from robotwright.render import RenderError, RenderOptions, render_model
from robotwright.render import gl as gl_module
from robotwright.render.anim import animate, sweep_states
from robotwright.render.core import RenderSession

_ARM = """<mujoco><worldbody><light pos="0 0 3"/>
<geom type="plane" size="1 1 0.1" rgba=".8 .8 .8 1"/>
<body pos="0 0 0.3"><joint name="j" type="hinge" axis="0 1 0" range="-1 1"/>
<geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.04" rgba=".2 .4 .9 1"/></body>
</worldbody></mujoco>"""


@pytest.fixture()
def contexts(monkeypatch) -> list[str]:
    """Every GL context the renderer tries to make, by platform."""
    made: list[str] = []
    real = gl_module._context

    def counting(platform: str, width: int, height: int):
        made.append(platform)
        return real(platform, width, height)

    monkeypatch.setattr(gl_module, "_context", counting)
    return made


@pytest.mark.parametrize("frames", [3, 7])
def test_one_context_per_animation_whatever_the_frame_count(contexts, frames) -> None:
    model = mujoco.MjModel.from_xml_string(_ARM)
    states = sweep_states(model, model.qpos0.copy(), frames)
    anim = animate(model, states, np.arange(frames) / 10.0, 10.0, RenderOptions(64, 48))
    assert anim.frames.shape[0] == frames
    # one context when a platform starts; each platform tried once when none does
    assert len(contexts) == (1 if anim.backend.startswith("gl-") else len(set(contexts)))
    assert len(contexts) == len(set(contexts))


def test_session_frames_equal_single_pictures() -> None:
    model = mujoco.MjModel.from_xml_string(_ARM)
    data = mujoco.MjData(model)
    opts = RenderOptions(64, 48, camera="90,-20")
    with RenderSession(model, opts) as session:
        for q in (-0.8, 0.0, 0.6):
            data.qpos[0] = q
            mujoco.mj_forward(model, data)
            shared = render_model(model, data, opts, session=session)
            alone = render_model(model, data, opts)
            assert shared.backend == alone.backend
            np.testing.assert_array_equal(shared.image, alone.image)


def test_session_refuses_other_options() -> None:
    model = mujoco.MjModel.from_xml_string(_ARM)
    with RenderSession(model, RenderOptions(64, 48)) as session, pytest.raises(RenderError):
        render_model(model, None, RenderOptions(32, 24), session=session)


def test_a_platform_that_cannot_start_is_tried_once_per_animation(monkeypatch) -> None:
    tried: list[str] = []

    def refuse(platform: str, width: int, height: int):
        tried.append(platform)
        raise RuntimeError("no display here")

    monkeypatch.setattr(gl_module, "_context", refuse)
    monkeypatch.setattr(gl_module, "gl_platforms", lambda: ["egl", "osmesa"])
    model = mujoco.MjModel.from_xml_string(_ARM)
    states = sweep_states(model, model.qpos0.copy(), 5)
    anim = animate(model, states, np.arange(5) / 10.0, 10.0, RenderOptions(64, 48))
    assert anim.backend == "software" and tried == ["egl", "osmesa"]
    assert any("OpenGL unavailable" in n and "no display here" in n for n in anim.notes)
