"""The three sides a round trip compares: the source as MuJoCo (or yourdfpy) reads it, our
MJCF and our URDF of the parsed robot, each as a view of the compiled model."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from robotwright._names import shown
from robotwright._paths import trusted_asset_roots
from robotwright.hrdf.model import HRDF
from robotwright.parsers.reference import (
    JointInfo,
    RobotView,
    compile_urdf,
    urdf_for_mujoco,
    urdf_yourdfpy_view,
    view_from_model,
)


# -- whole round trips ----------------------------------------------------------------------
def source_kind(path: Path) -> str:
    ext = path.suffix.lower()
    if ext in (".urdf", ".xacro"):
        return "urdf"
    if ext == ".xml" or ext == ".mjcf":
        return "mjcf"
    raise ValueError(f"{path}: expected a .urdf, .xacro or .xml (MJCF) file")


def parse_source(path: Path, strict: bool = False, **options: Any):
    """ParseResult of an MJCF or URDF file (by extension)."""
    from robotwright.parsers.api import mjcf_to_hrdf_with_warnings, urdf_to_hrdf_with_warnings

    if source_kind(path) == "urdf":
        return urdf_to_hrdf_with_warnings(path, strict=strict, **options)
    return mjcf_to_hrdf_with_warnings(path, strict=strict, **options)


def our_mjcf_text(hrdf: HRDF) -> str:
    """Our MJCF of ``hrdf`` as a string (no scene, mesh paths absolute)."""
    from robotwright.generators.compiles import robot_xml

    return robot_xml(hrdf)


def our_mjcf_model(hrdf: HRDF) -> mujoco.MjModel:
    """Our MJCF of ``hrdf`` compiled by MuJoCo (no scene)."""
    from robotwright._mjspec_cache import compiled

    return compiled(our_mjcf_text(hrdf))


@dataclass
class OurURDF:
    """Our URDF of a robot, ready for MuJoCo's import (:func:`urdf_for_mujoco`), with the
    links the URDF form adds: dummy links (link -> the body it splits) and frame links
    (site -> its link)."""

    text: str
    dummy_links: dict[str, str]
    frame_links: dict[str, str]
    #: ball joint -> the x, y, z revolute joints our URDF writes for it.
    split_joints: dict[str, tuple[str, str, str]] = field(default_factory=dict)

    def view(self, model: mujoco.MjModel) -> RobotView:
        """View of ``model`` (this URDF compiled) without the links the URDF form adds:
        dummy links (their 1e-9 kg each stays in the total mass) and site links renamed
        because a body has the site's name (the reference's FK of that name is the body).
        A ball joint is one joint of the view again: its FK takes the ball's quaternion
        and sets the three revolute joints that stand for it to the same rotation."""
        view = view_from_model(model)
        drop = set(self.dummy_links)
        drop |= {link for site, link in self.frame_links.items() if link != site}
        view.bodies = [b for b in view.bodies if b not in drop]
        view.inertia_world = {k: v for k, v in view.inertia_world.items() if k not in drop}
        view.mass = {k: v for k, v in view.mass.items() if k not in drop or k in self.dummy_links}
        if self.split_joints:
            _join_split_balls(view, self.split_joints)
        return view


def xyz_angles(quat: np.ndarray) -> tuple[float, float, float]:
    """Angles ``(a, b, c)`` (rad) with ``Rx(a) Ry(b) Rz(c)`` the rotation of the unit
    quaternion ``quat`` (w, x, y, z): a rotation about x, then about the new y, then
    about the newest z, as the revolute joints standing for a ball joint turn."""
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, np.asarray(quat, dtype=float))
    r = mat.reshape(3, 3)
    b = float(np.arctan2(r[0, 2], np.hypot(r[0, 0], r[0, 1])))
    a = float(np.arctan2(-r[1, 2], r[2, 2]))
    c = float(np.arctan2(-r[0, 1], r[0, 0]))
    return a, b, c


def _join_split_balls(view: RobotView, split: dict[str, tuple[str, str, str]]) -> None:
    """Turn the revolute joints standing for each ball joint back into that ball joint
    of ``view`` (joints and FK)."""
    joints = {j.name: j for j in view.joints}
    parts = {n for names in split.values() for n in names}
    balls = {ball: names for ball, names in split.items() if all(n in joints for n in names)}
    kept = []
    for j in view.joints:
        ball = next((b for b, names in balls.items() if j.name == names[0]), None)
        if ball is not None:
            last = joints[balls[ball][2]]
            kept.append(JointInfo(ball, "ball", last.body, np.zeros(3), None))
        elif j.name not in parts:
            kept.append(j)
    view.joints = kept
    inner = view.fk

    def fk(q: dict[str, Any]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        q = dict(q)
        for ball, names in balls.items():
            if ball in q:
                q.update(zip(names, xyz_angles(q.pop(ball)), strict=True))
        return inner(q)  # type: ignore[operator]

    view.fk = fk


def our_urdf(hrdf: HRDF) -> OurURDF:
    """Our URDF of ``hrdf``, with mesh paths absolute (files of the robot, or of the
    parser's staging folder: keep the robot until MuJoCo has loaded the text)."""
    import warnings

    from robotwright.generators import URDFHumanoidGenerator

    gen = URDFHumanoidGenerator.from_hrdf(hrdf)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        root = gen.generate(relative_mesh_path=False)
    # The generated tree as is: the same document export writes, less its indentation.
    text = urdf_for_mujoco(Path(f"{hrdf.name}.urdf"), root=root)
    return OurURDF(text, dict(gen.dummy_links), dict(gen.frame_links), dict(gen.split_joints))


def our_urdf_model(hrdf: HRDF) -> mujoco.MjModel:
    """Our URDF of ``hrdf`` loaded by MuJoCo (every link kept, inertia from <inertial>)."""
    return compile_urdf(our_urdf(hrdf).text)


def our_urdf_view(hrdf: HRDF) -> RobotView:
    """View of our URDF in MuJoCo without the links the URDF form adds (see
    :meth:`OurURDF.view`)."""
    ours = our_urdf(hrdf)
    return ours.view(compile_urdf(ours.text))


def _check_reference(reference: str) -> None:
    if reference not in ("auto", "mujoco", "yourdfpy"):
        raise ValueError(f"reference={shown(reference)}: expected 'auto', 'mujoco' or 'yourdfpy'")


@dataclass
class ReferenceLoader:
    """The reference of a round trip, in steps: the text MuJoCo will import is prepared
    on construction (see :func:`reference_loader`); :meth:`load` does the import
    (MuJoCo's work, which may run on another thread: MuJoCo releases the interpreter
    while it parses and compiles) and raises ValueError when MuJoCo refuses the source;
    :meth:`instead` is the view to use then."""

    load: Callable[[], RobotView]
    #: For a URDF MuJoCo refuses, with ``reference="auto"``: yourdfpy's view (None: the
    #: refusal is the answer).
    fallback: Callable[[ValueError], RobotView] | None = None
    #: Starts the import in a confined reader now and returns the wait for its view
    #: (see :func:`robotwright._confine.start_confined`); None: :attr:`load` it is.
    start: Callable[[], Callable[[], RobotView]] | None = None

    def started(self) -> Callable[[], RobotView]:
        """The import, started now (before other threads run MuJoCo)."""
        return self.start() if self.start is not None else self.load

    def instead(self, exc: ValueError) -> RobotView:
        if self.fallback is None:
            raise exc
        return self.fallback(exc)

    def __call__(self) -> RobotView:
        try:
            return self.load()
        except ValueError as exc:
            return self.instead(exc)


def _yourdfpy_instead(path: Path, compiler: dict[str, Any], exc: ValueError) -> RobotView:
    view = urdf_yourdfpy_view(path, **compiler)
    view.kind = f"yourdfpy (MuJoCo refuses the source: {str(exc).splitlines()[0][:120]})"
    return view


def reference_loader(path: Path, reference: str = "auto", **options: Any) -> ReferenceLoader:
    """The reference of ``path`` (see :func:`reference_view`), prepared to be loaded."""
    _check_reference(reference)
    from robotwright._confine import start_confined
    from robotwright.parsers.packages import source_read_roots

    roots = source_read_roots(path, source_kind(path), options)
    from robotwright.parsers.api import prepare_read

    prepare_read()
    if source_kind(path) == "mjcf":
        root = options.get("root_body")

        def start_mjcf() -> Callable[[], RobotView]:
            call = start_confined(_model_from_path, str(path), roots=roots, what=str(path))
            return lambda: view_from_model(call(), root=root)

        return ReferenceLoader(lambda: start_mjcf()(), start=start_mjcf)
    compiler = {
        k: options[k] for k in ("balance_inertia", "bound_mass", "bound_inertia") if k in options
    }
    if reference == "yourdfpy":
        return ReferenceLoader(lambda: urdf_yourdfpy_view(path, **compiler))
    fallback = (
        None if reference == "mujoco" else functools.partial(_yourdfpy_instead, path, compiler)
    )
    try:
        # The source's mesh paths under the parsers' containment rule (trusted folders:
        # the caller's asset_roots and those of an enclosing --asset-root).
        with trusted_asset_roots(options.get("asset_roots") or ()):
            text = urdf_for_mujoco(
                path,
                options.get("package_map"),
                inertia_from_geoms=options.get("inertia_from_geoms", "auto"),
                **compiler,
            )
    except ValueError as exc:
        if fallback is None:
            raise
        return ReferenceLoader(functools.partial(fallback, exc))  # yourdfpy's from the start
    density = options.get("density")  # of links without <inertial>, as the parser's
    # The free base the user asked for, as the parser gives it: not a difference.
    floating = bool(options.get("floating_base"))

    def start_urdf() -> Callable[[], RobotView]:
        call = start_confined(
            compile_urdf, text, density, floating=floating, roots=roots, what=str(path)
        )
        return lambda: view_from_model(call(), "mujoco")

    return ReferenceLoader(lambda: start_urdf()(), fallback, start=start_urdf)


def _model_from_path(path: str) -> mujoco.MjModel:
    """MuJoCo's compile of the MJCF file ``path`` (run confined)."""
    return mujoco.MjModel.from_xml_path(path)


def reference_view(path: Path, reference: str = "auto", **options: Any) -> RobotView:
    """The source as MuJoCo compiles it; for a URDF MuJoCo refuses (or with
    ``reference="yourdfpy"``), yourdfpy's view."""
    return reference_loader(path, reference, **options)()
