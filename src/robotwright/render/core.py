"""Pictures of a compiled MuJoCo model: ``render_model`` and its options.

MuJoCo decides what is drawn (``mjv_updateScene``: visible geom and site groups,
colours, materials, poses, the camera); the picture is then drawn by MuJoCo's OpenGL
renderer where a GL platform can start (:mod:`robotwright.render.gl`), otherwise by
the numpy z-buffer rasteriser (:mod:`robotwright.render.raster`), which draws the same
geoms and meshes with flat Lambert shading. :attr:`Picture.backend` says which ran.
Points (a LiDAR scan) can be drawn into the picture with a depth test, so that walls
hide the points behind them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import mujoco
import numpy as np

from robotwright.errors import RobotwrightError
from robotwright.render.camera import CameraSpec, make_camera, parse_camera
from robotwright.render.gl import GLSession, GLUnavailable, render_gl
from robotwright.render.meshes import scene_triangles
from robotwright.render.raster import View, rasterise, shade

__all__ = ["Picture", "RenderError", "RenderOptions", "render_model"]

Backend = Literal["auto", "gl", "software"]

#: Largest picture side [px]: a larger one is a typo more often than a wish (and the
#: software renderer holds several float arrays of the picture's size).
MAX_SIDE = 4096
#: MuJoCo's geom groups (mjNGROUP) and the ones its viewer shows by default.
GEOM_GROUPS = 6
DEFAULT_GEOM_GROUPS = (0, 1, 2)
#: Most geoms MuJoCo may put in the scene (robots with sites, composed scenes).
_MAX_SCENE_GEOMS = 20_000
#: Background, top and bottom rows (a light sky gradient: geoms stand out from it).
_SKY_TOP = np.array([0.72, 0.80, 0.90])
_SKY_BOTTOM = np.array([0.96, 0.97, 0.98])


class RenderError(RobotwrightError, ValueError):
    """Bad picture options, or a picture that cannot be drawn as asked."""


@dataclass(frozen=True)
class RenderOptions:
    """How a picture is drawn.

    Attributes:
        width, height: picture size [px], each in 16..4096.
        camera: a model camera's name, a view (``iso``, ``front``, ``back``, ``left``,
            ``right``, ``top``) or ``AZ,EL[,DIST]`` (degrees, metres); see
            :mod:`robotwright.render.camera`.
        backend: ``"auto"`` (OpenGL when a platform starts, else software), ``"gl"``
            (OpenGL or an error) or ``"software"`` (numpy rasteriser).
        supersample: the software renderer draws at this multiple of the size and
            averages down (smooth edges); 1..4, lowered for large pictures (at most
            3000 x 3000 pixels are drawn).
        point_radius: radius of a drawn point [px].
        geom_groups: MuJoCo geom groups drawn (0..5; MuJoCo's default 0, 1, 2).
            Robots often keep collision geoms in group 3: leave it out to hide them.
    """

    width: int = 800
    height: int = 600
    camera: str = "iso"
    backend: Backend = "auto"
    supersample: int = 2
    point_radius: float = 1.5
    geom_groups: tuple[int, ...] = DEFAULT_GEOM_GROUPS

    def __post_init__(self) -> None:
        for name in ("width", "height"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or not 16 <= v <= MAX_SIDE:
                raise RenderError(
                    f"picture {name} {v!r}: expected an integer in 16..{MAX_SIDE} [px]"
                )
        if self.backend not in ("auto", "gl", "software"):
            raise RenderError(f"backend {self.backend!r}: expected 'auto', 'gl' or 'software'")
        if isinstance(self.supersample, bool) or self.supersample not in (1, 2, 3, 4):
            raise RenderError(f"supersample {self.supersample!r}: expected 1, 2, 3 or 4")
        if not (math.isfinite(self.point_radius) and 0 < self.point_radius <= 20):
            raise RenderError(f"point_radius {self.point_radius!r}: expected (0, 20] px")
        groups = self.geom_groups
        if not isinstance(groups, tuple) or any(
            isinstance(g, bool) or not isinstance(g, int) or not 0 <= g < GEOM_GROUPS
            for g in groups
        ):
            raise RenderError(
                f"geom_groups {groups!r}: expected a tuple of MuJoCo geom groups "
                f"0..{GEOM_GROUPS - 1}"
            )
        parse_camera(self.camera)  # raises CameraError naming the problem

    @property
    def camera_spec(self) -> CameraSpec:
        return parse_camera(self.camera)


@dataclass
class Picture:
    """A drawn picture.

    Attributes:
        image: ``(height, width, 3)`` uint8 RGB, row 0 at the top.
        backend: what drew it: ``"gl-egl"``, ``"gl-osmesa"``, ``"gl-glfw"`` or
            ``"software"``.
        camera: the camera as given.
        notes: what was not drawn and why OpenGL was not used, one line each.
        depth: ``(height, width)`` distance along the view axis [m], ``inf`` for
            background.
    """

    image: np.ndarray
    backend: str
    camera: str
    notes: list[str] = field(default_factory=list)
    depth: np.ndarray | None = None


def _scene(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    cam: mujoco.MjvCamera,
    groups: tuple[int, ...] = DEFAULT_GEOM_GROUPS,
    scene: mujoco.MjvScene | None = None,
) -> mujoco.MjvScene:
    """MuJoCo's scene of ``data`` seen by ``cam``, with the geoms of ``groups`` only
    (filled into ``scene`` when given, else into a new one)."""
    if scene is None:
        scene = mujoco.MjvScene(model, maxgeom=_MAX_SCENE_GEOMS)
    option = mujoco.MjvOption()
    option.geomgroup[:] = [int(g in groups) for g in range(GEOM_GROUPS)]
    mujoco.mjv_updateScene(
        model, data, option, mujoco.MjvPerturb(), cam, mujoco.mjtCatBit.mjCAT_ALL, scene
    )
    return scene


def drawn_bounds(model: mujoco.MjModel, scene: mujoco.MjvScene) -> np.ndarray:
    """Corners ``(8 * G, 3)`` [m] of the world boxes of the geoms in ``scene`` (planes
    left out: an infinite floor has no bounds to frame)."""
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    corners = []
    for i in range(scene.ngeom):
        g = scene.geoms[i]
        t = int(g.type)
        if t == int(mujoco.mjtGeom.mjGEOM_PLANE) or t >= int(mujoco.mjtGeom.mjGEOM_ARROW):
            continue
        if int(g.objtype) == mujoco.mjtObj.mjOBJ_GEOM and g.objid >= 0:
            centre, half = model.geom_aabb[g.objid][:3], model.geom_aabb[g.objid][3:]
        else:  # sites and the like: a sphere of their largest size
            centre, half = np.zeros(3), np.full(3, float(np.max(g.size)))
        rot = np.asarray(g.mat, dtype=np.float64).reshape(3, 3)
        local = centre + signs * half
        corners.append(local @ rot.T + np.asarray(g.pos, dtype=np.float64))
    return np.concatenate(corners) if corners else np.zeros((0, 3))


def _view(scene: mujoco.MjvScene, width: int, height: int) -> View:
    # MuJoCo places camera[0] and camera[1] half an eye distance left and right of
    # the head; a mono picture is taken from their average, as mjr_render does.
    cam = mujoco.mjv_averageCamera(scene.camera[0], scene.camera[1])
    top, bottom = float(cam.frustum_top), float(cam.frustum_bottom)
    # As mjr_render: the frustum's width follows the picture's aspect ratio.
    half = 0.5 * (top - bottom) * width / height
    centre = float(cam.frustum_center)
    forward = np.asarray(cam.forward, dtype=np.float64)
    up = np.asarray(cam.up, dtype=np.float64)
    forward /= np.linalg.norm(forward)
    up -= forward * (up @ forward)
    up /= np.linalg.norm(up)
    return View(
        pos=np.asarray(cam.pos, dtype=np.float64),
        forward=forward,
        up=up,
        near=float(cam.frustum_near),
        left=centre - half,
        right=centre + half,
        bottom=bottom,
        top=top,
        orthographic=bool(cam.orthographic),
    )


def _sky(height: int, width: int) -> np.ndarray:
    t = np.linspace(0.0, 1.0, height)[:, None, None]
    return np.broadcast_to(_SKY_TOP * (1 - t) + _SKY_BOTTOM * t, (height, width, 3))


def _lights(scene: mujoco.MjvScene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    dirs, diffuse, ambient = [], [], np.zeros(3)
    for i in range(scene.nlight):
        light = scene.lights[i]
        d = np.asarray(light.dir, dtype=np.float64)
        n = np.linalg.norm(d)
        if n > 0:
            dirs.append(d / n)
            diffuse.append(np.asarray(light.diffuse, dtype=np.float64))
        ambient += np.asarray(light.ambient, dtype=np.float64)
    if not dirs:  # MuJoCo with no light at all draws by ambient alone; keep shapes readable
        return np.zeros((0, 3)), np.zeros((0, 3)), np.maximum(ambient, 0.6)
    return np.array(dirs), np.array(diffuse), ambient


def _checker(
    image: np.ndarray, frame_face: np.ndarray, depth: np.ndarray, view: View, checker: np.ndarray
) -> None:
    """Darken every other cell (world x, y) of textured planes (the software renderer
    samples no textures; a checker keeps a floor readable as a floor)."""
    mask = frame_face >= 0
    mask[mask] = checker[frame_face[mask]] > 0
    if not mask.any():
        return
    h, w = depth.shape
    ys, xs = np.nonzero(mask)
    sx = view.left + (xs + 0.5) / w * (view.right - view.left)
    sy = view.top - (ys + 0.5) / h * (view.top - view.bottom)
    d = depth[ys, xs]
    if view.orthographic:
        world = view.pos + np.outer(sx, view.right_axis) + np.outer(sy, view.up)
        world += np.outer(d, view.forward)
    else:
        ray = np.outer(sx, view.right_axis) + np.outer(sy, view.up) + view.near * view.forward
        world = view.pos + ray * (d / view.near)[:, None]
    cell = checker[frame_face[ys, xs]]
    parity = (np.floor(world[:, 0] / cell) + np.floor(world[:, 1] / cell)) % 2 == 1
    image[ys[parity], xs[parity]] *= 0.8


#: Most pixels the software renderer draws before averaging down: a large picture gets
#: less supersampling (memory grows with the pixels drawn: about 2 GB at 4096 x 3000).
_MAX_DRAWN_PIXELS = 3000 * 3000


def _supersample(opts: RenderOptions) -> int:
    """The supersampling factor used: the option, lowered for large pictures."""
    fit = int(math.sqrt(_MAX_DRAWN_PIXELS / (opts.width * opts.height)))
    return max(1, min(opts.supersample, fit))


def _software(
    model: mujoco.MjModel, scene: mujoco.MjvScene, opts: RenderOptions, notes: list[str]
) -> tuple[np.ndarray, np.ndarray, View, int]:
    """Float RGB ``(sH, sW, 3)``, depth, view and the supersampling factor used."""
    ss = _supersample(opts)
    w, h = opts.width * ss, opts.height * ss
    view = _view(scene, w, h)
    reach = max(float(model.stat.extent) * 10.0, 10.0)
    tris = scene_triangles(model, scene, plane_reach=reach)
    notes += [f"not drawn: {s}" for s in tris.skipped]
    colours = shade(tris.vertices, tris.rgba, view, *_lights(scene))
    # Opaque triangles first; then the nearest partly transparent surface in front of
    # them is blended over by its alpha (one layer: enough for a glass cover or a
    # see-through marker, not for stacks of them).
    opaque = tris.rgba[:, 3] >= 0.999
    ids = np.nonzero(opaque)[0]
    frame = rasterise(tris.vertices[ids], view, w, h)
    face = np.where(frame.face >= 0, ids[np.maximum(frame.face, 0)], -1)
    image = _sky(h, w).copy()
    hit = face >= 0
    image[hit] = colours[face[hit]]
    _checker(image, face, frame.depth, view, tris.checker)
    if not opaque.all():
        ids = np.nonzero(~opaque)[0]
        glass = rasterise(tris.vertices[ids], view, w, h)
        over = (glass.face >= 0) & (glass.depth < frame.depth)
        top = ids[glass.face[over]]
        alpha = tris.rgba[top, 3:4]
        image[over] = alpha * colours[top] + (1.0 - alpha) * image[over]
    return image, frame.depth, view, ss


def _draw_points(
    image: np.ndarray,
    depth: np.ndarray,
    view: View,
    points: np.ndarray,
    colours: np.ndarray,
    radius: float,
) -> None:
    """Draw points as discs of ``radius`` px where no surface is in front of them."""
    h, w = depth.shape
    cam = view.to_camera(points)
    front = cam[:, 2] > view.near
    cam, colours = cam[front], colours[front]
    pix = view.to_pixels(cam, w, h)
    # A point on a surface sits at that surface's depth: allow 2 % + 2 cm of slack.
    ix, iy = np.floor(pix[:, 0]).astype(np.int64), np.floor(pix[:, 1]).astype(np.int64)
    inside = (ix >= 0) & (ix < w) & (iy >= 0) & (iy < h)
    ix, iy, z, colours = ix[inside], iy[inside], cam[inside, 2], colours[inside]
    seen = z <= depth[iy, ix] * 1.02 + 0.02
    ix, iy, z, colours = ix[seen], iy[seen], z[seen], colours[seen]
    order = np.argsort(-z)  # far first, so that near points are drawn over far ones
    ix, iy, colours = ix[order], iy[order], colours[order]
    r = int(math.ceil(radius))
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            if dx * dx + dy * dy > radius * radius + 0.25:
                continue
            x, y = ix + dx, iy + dy
            ok = (x >= 0) & (x < w) & (y >= 0) & (y < h)
            image[y[ok], x[ok]] = colours[ok]


class RenderSession:
    """What the frames of one animation share: one MuJoCo scene, and one OpenGL context
    made at the first frame drawn with OpenGL (:class:`~robotwright.render.gl.GLSession`;
    a platform that cannot start is tried once, not at every frame). Close it (or use it
    in a ``with`` block) to free the context.
    """

    def __init__(self, model: mujoco.MjModel, options: RenderOptions) -> None:
        self.model, self.options = model, options
        self.scene = mujoco.MjvScene(model, maxgeom=_MAX_SCENE_GEOMS)
        self._gl: GLSession | None = None
        self._gl_refused: GLUnavailable | None = None

    def gl(self) -> GLSession:
        """The session's GL context, made on first use.

        Raises:
            GLUnavailable: no platform could start (raised again on every later call).
        """
        if self._gl is None:
            if self._gl_refused is not None:
                raise self._gl_refused
            try:
                self._gl = GLSession(self.model, self.options.width, self.options.height)
            except GLUnavailable as exc:
                self._gl_refused = exc
                raise
        return self._gl

    def close(self) -> None:
        if self._gl is not None:
            self._gl.close()
            self._gl = None

    def __enter__(self) -> RenderSession:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def render_model(
    model: mujoco.MjModel,
    data: mujoco.MjData | None = None,
    options: RenderOptions | None = None,
    *,
    points: np.ndarray | None = None,
    point_colors: np.ndarray | None = None,
    bounds: np.ndarray | None = None,
    session: RenderSession | None = None,
) -> Picture:
    """Draw ``model`` in the state ``data`` (``qpos0`` after ``mj_forward`` if None).

    Args:
        model: a compiled model.
        data: its state; forward kinematics must be current (``mj_forward``).
        options: size, camera, backend; defaults to :class:`RenderOptions`.
        points: ``(N, 3)`` world-frame points [m] to draw over the scene (e.g. LiDAR
            hits), hidden where a surface is in front of them.
        point_colors: ``(N, 3)`` RGB in [0, 1] per point (default black).
        bounds: ``(K, 3)`` world points [m] a free camera frames instead of what is
            drawn (the frames of an animation share one camera this way).
        session: the scene and GL context shared with other frames of the same model
            and ``options`` (see :class:`RenderSession`); None makes and frees them here.

    Raises:
        RenderError: bad options or points; ``backend="gl"`` with no GL platform.
        CameraError: the camera names no camera of the model.
    """
    opts = options or RenderOptions()
    if data is None:
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
    pts, cols = _check_points(points, point_colors)
    spec = opts.camera_spec
    if session is not None and (session.model is not model or session.options != opts):
        raise RenderError("a render session draws the model and options it was made for")
    buffer = None if session is None else session.scene
    if bounds is None:
        corners = drawn_bounds(
            model, _scene(model, data, mujoco.MjvCamera(), opts.geom_groups, buffer)
        )
    else:
        corners = np.asarray(bounds, dtype=np.float64).reshape(-1, 3)
    if pts is not None and len(pts):  # the points are framed too (a scan without scene)
        corners = np.concatenate([corners, pts.min(axis=0)[None], pts.max(axis=0)[None]])
    cam = make_camera(model, spec, corners, opts.width / opts.height)
    scene = _scene(model, data, cam, opts.geom_groups, buffer)
    notes: list[str] = []
    image: np.ndarray | None = None
    backend = "software"
    if opts.backend in ("auto", "gl"):
        # No skybox: both renderers draw the same plain sky behind the model, and the
        # depth buffer tells the model from the background.
        scene.flags[mujoco.mjtRndFlag.mjRND_SKYBOX] = 0
        try:
            if session is None:
                gl = render_gl(model, scene, opts.width, opts.height)
            else:
                gl = session.gl().draw(scene)
        except GLUnavailable as exc:
            if opts.backend == "gl":
                raise RenderError(f"no OpenGL platform could draw: {exc}") from None
            notes.append(f"OpenGL unavailable, drawn by the software renderer ({exc})")
        else:
            backend = f"gl-{gl.platform}"
            image, depth, ss = gl.rgb.astype(np.float64) / 255.0, gl.depth, 1
            view = _view(scene, opts.width, opts.height)
            bg = ~np.isfinite(depth)
            image[bg] = _sky(opts.height, opts.width)[bg]
    if image is None:
        image, depth, view, ss = _software(model, scene, opts, notes)
    if pts is not None:
        _draw_points(image, depth, view, pts, cols, opts.point_radius * ss)
    if ss > 1:
        h, w = opts.height, opts.width
        image = image.reshape(h, ss, w, ss, 3).mean(axis=(1, 3))
        depth = depth.reshape(h, ss, w, ss).min(axis=(1, 3))
    rgb = np.clip(np.round(image * 255.0), 0, 255).astype(np.uint8)
    return Picture(rgb, backend, spec.text, notes, depth)


def _check_points(
    points: np.ndarray | None, colors: np.ndarray | None
) -> tuple[np.ndarray | None, np.ndarray | None]:
    if points is None:
        if colors is not None:
            raise RenderError("point_colors given without points")
        return None, None
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise RenderError(f"points: expected shape (N, 3) [m], got {pts.shape}")
    finite = np.isfinite(pts).all(axis=1)
    if colors is None:
        cols = np.zeros((len(pts), 3))
    else:
        cols = np.asarray(colors, dtype=np.float64)
        if cols.shape != pts.shape:
            raise RenderError(f"point_colors: expected shape {pts.shape}, got {cols.shape}")
        if not ((cols >= 0) & (cols <= 1)).all():
            raise RenderError("point_colors: expected RGB values in [0, 1]")
    return pts[finite], cols[finite]
