"""A z-buffer triangle rasteriser in numpy: the renderer used where no OpenGL is.

Triangles are clipped against the near plane, projected with the camera MuJoCo
computed for the scene (``MjvScene.camera[0]``: position, forward and up axes,
frustum), and filled with a per-pixel depth test, many triangles per numpy call.
Shading is flat Lambert per triangle with the scene's lights (MuJoCo's headlight and
the model's lights, all treated as directional).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Frame", "View", "rasterise", "shade"]

#: Pixels and pixel rows handled per numpy call (bound the memory of one batch).
_BATCH_FRAGMENTS = 2_000_000
_BATCH_ROWS = 500_000


@dataclass(frozen=True)
class View:
    """A pinhole (or orthographic) camera in the world frame.

    Attributes:
        pos: camera position [m], shape ``(3,)``.
        forward: unit viewing direction, shape ``(3,)``.
        up: unit up direction, orthogonal to ``forward``, shape ``(3,)``.
        near: near clipping distance [m] (the frustum is given at this distance).
        left, right, bottom, top: frustum bounds at distance ``near`` [m] (for an
            orthographic camera: the half extents of the view in metres).
        orthographic: parallel projection instead of perspective.
    """

    pos: np.ndarray
    forward: np.ndarray
    up: np.ndarray
    near: float
    left: float
    right: float
    bottom: float
    top: float
    orthographic: bool = False

    @property
    def right_axis(self) -> np.ndarray:
        return np.cross(self.forward, self.up)

    def to_camera(self, points: np.ndarray) -> np.ndarray:
        """World points ``(..., 3)`` -> camera coordinates (right, up, depth) [m]."""
        basis = np.stack([self.right_axis, self.up, self.forward])
        return (points - self.pos) @ basis.T

    def to_pixels(self, cam: np.ndarray, width: int, height: int) -> np.ndarray:
        """Camera coordinates ``(..., 3)`` with depth > 0 -> pixel ``(x, y)`` (x right,
        y down, pixel centres at half integers)."""
        if self.orthographic:
            sx, sy = cam[..., 0], cam[..., 1]
        else:
            sx = cam[..., 0] * self.near / cam[..., 2]
            sy = cam[..., 1] * self.near / cam[..., 2]
        px = (sx - self.left) / (self.right - self.left) * width
        py = (self.top - sy) / (self.top - self.bottom) * height
        return np.stack([px, py], axis=-1)


@dataclass
class Frame:
    """The rasteriser's output.

    Attributes:
        face: ``(H, W)`` index of the triangle seen at each pixel, -1 for none.
        depth: ``(H, W)`` distance along the view axis [m], ``inf`` for none.
    """

    face: np.ndarray
    depth: np.ndarray


def _clip_near(cam: np.ndarray, ids: np.ndarray, near: float) -> tuple[np.ndarray, np.ndarray]:
    """Clip triangles ``(T, 3, 3)`` in camera coordinates against depth >= ``near``.
    A triangle with one corner behind becomes two, with two behind becomes one."""
    behind = cam[:, :, 2] < near
    n = behind.sum(axis=1)
    keep_c, keep_i = [cam[n == 0]], [ids[n == 0]]
    for count in (1, 2):
        sel = n == count
        if not sel.any():
            continue
        tri, tid, b = cam[sel], ids[sel], behind[sel]
        # Roll each triangle so that the odd corner (the one behind when count is 1,
        # the one in front when count is 2) comes first; winding is kept.
        odd = np.argmax(b if count == 1 else ~b, axis=1)
        order = (odd[:, None] + np.arange(3)[None, :]) % 3
        tri = np.take_along_axis(tri, order[:, :, None], axis=1)
        a, p, q = tri[:, 0], tri[:, 1], tri[:, 2]

        def cut(u: np.ndarray, v: np.ndarray) -> np.ndarray:
            t = (near - u[:, 2]) / (v[:, 2] - u[:, 2])
            return u + t[:, None] * (v - u)

        ap, aq = cut(a, p), cut(a, q)
        if count == 1:  # a behind: quad ap, p, q, aq
            keep_c += [np.stack([ap, p, q], 1), np.stack([ap, q, aq], 1)]
            keep_i += [tid, tid]
        else:  # only a in front
            keep_c.append(np.stack([a, ap, aq], 1))
            keep_i.append(tid)
    return np.concatenate(keep_c), np.concatenate(keep_i)


def rasterise(triangles: np.ndarray, view: View, width: int, height: int) -> Frame:
    """Depth-test the world-frame ``triangles`` ``(T, 3, 3)`` into a ``width`` x
    ``height`` frame seen by ``view``.

    Each triangle is cut into pixel rows; each row's covered span comes from the three
    edge equations, so only covered pixels are visited. Depth is tested on ``1/z``
    (perspective) or ``-z`` (orthographic), both affine in screen space.
    """
    face = np.full(height * width, -1, dtype=np.int64)
    key_buf = np.full(height * width, -np.inf)
    if len(triangles) == 0:
        return Frame(face.reshape(height, width), np.full((height, width), np.inf))
    cam = view.to_camera(triangles)
    ids = np.arange(len(triangles))
    if not view.orthographic:
        cam, ids = _clip_near(cam, ids, view.near)
    if len(cam) == 0:
        return Frame(face.reshape(height, width), np.full((height, width), np.inf))
    pix = view.to_pixels(cam, width, height)  # (T, 3, 2)
    key = -cam[:, :, 2] if view.orthographic else 1.0 / cam[:, :, 2]
    # Edge i is opposite corner i: w_i(x, y) = A_i x + B_i y + C_i, the barycentric
    # weight of corner i once divided by the signed area (either winding is drawn).
    a, b = pix[:, [1, 2, 0]], pix[:, [2, 0, 1]]
    A = -(b[..., 1] - a[..., 1])
    B = b[..., 0] - a[..., 0]
    C = (b[..., 1] - a[..., 1]) * a[..., 0] - (b[..., 0] - a[..., 0]) * a[..., 1]
    area = C.sum(axis=1)  # sum of the w_i at any point = twice the signed area
    y0 = np.clip(np.ceil(pix[:, :, 1].min(1) - 0.5), 0, height).astype(np.int64)
    y1 = np.clip(np.floor(pix[:, :, 1].max(1) - 0.5) + 1, 0, height).astype(np.int64)
    ok = (np.abs(area) > 1e-12) & (y1 > y0)
    A, B, C, area, key, ids, y0, y1 = (v[ok] for v in (A, B, C, area, key, ids, y0, y1))
    A, B, C = A / area[:, None], B / area[:, None], C / area[:, None]
    zx, zy, z0 = (A * key).sum(1), (B * key).sum(1), (C * key).sum(1)
    rows_per = y1 - y0
    ends = np.cumsum(rows_per)
    start = 0
    while start < len(rows_per):
        # Triangles [start, stop) make one batch of about _BATCH_ROWS pixel rows.
        base = ends[start - 1] if start else 0
        stop = max(int(np.searchsorted(ends, base + _BATCH_ROWS, side="right")), start + 1)
        n = rows_per[start:stop]
        t = np.repeat(np.arange(start, stop), n)
        y = y0[t] + np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
        cy = y + 0.5
        rhs = -(B[t] * cy[:, None] + C[t])  # inside edge i: A_i * cx >= rhs_i
        At = A[t]
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = rhs / At
        lo = np.where(At > 0, bound, -np.inf).max(axis=1)
        hi = np.where(At < 0, bound, np.inf).min(axis=1)
        never = ((At == 0) & (rhs > 0)).any(axis=1)
        xs = np.clip(np.ceil(lo - 0.5), 0, width).astype(np.int64)
        xe = np.clip(np.floor(hi - 0.5) + 1, 0, width).astype(np.int64)
        count = np.where(never, 0, np.maximum(xe - xs, 0))
        r_ends = np.cumsum(count)
        r_start = 0
        while r_start < len(count):
            r_base = r_ends[r_start - 1] if r_start else 0
            r_stop = max(
                int(np.searchsorted(r_ends, r_base + _BATCH_FRAGMENTS, side="right")), r_start + 1
            )
            c = count[r_start:r_stop]
            r = np.repeat(np.arange(r_start, r_stop), c)
            k = np.arange(int(c.sum())) - np.repeat(np.cumsum(c) - c, c)
            tr = t[r]
            x = xs[r] + k
            z = zx[tr] * (x + 0.5) + zy[tr] * cy[r] + z0[tr]
            pid = y[r] * width + x
            np.maximum.at(key_buf, pid, z)
            win = z >= key_buf[pid]
            face[pid[win]] = ids[tr[win]]
            r_start = r_stop
        start = stop
    with np.errstate(divide="ignore"):
        depth = -key_buf if view.orthographic else np.where(key_buf > 0, 1.0 / key_buf, np.inf)
    depth = np.where(face >= 0, depth, np.inf)
    return Frame(face.reshape(height, width), depth.reshape(height, width))


def shade(
    triangles: np.ndarray,
    rgba: np.ndarray,
    view: View,
    light_dirs: np.ndarray,
    light_diffuse: np.ndarray,
    ambient: np.ndarray,
) -> np.ndarray:
    """Flat Lambert colour ``(T, 3)`` in [0, 1] of each triangle.

    Args:
        triangles: ``(T, 3, 3)`` world-frame corners [m].
        rgba: ``(T, 4)`` base colours.
        view: the camera (normals are turned to face it, so either winding is lit).
        light_dirs: ``(L, 3)`` unit directions the light travels in (world frame).
        light_diffuse: ``(L, 3)`` diffuse colour of each light.
        ambient: ``(3,)`` total ambient light.
    """
    if len(triangles) == 0:
        return np.zeros((0, 3))
    n = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    centre = triangles.mean(axis=1)
    to_eye = -view.forward if view.orthographic else view.pos - centre
    n *= np.where((n * to_eye).sum(axis=1) < 0, -1.0, 1.0)[:, None]
    light = np.broadcast_to(ambient, (len(n), 3)).copy()
    for d, c in zip(light_dirs, light_diffuse):
        light += np.clip(n @ -d, 0.0, None)[:, None] * c
    return np.clip(rgba[:, :3] * light, 0.0, 1.0)
