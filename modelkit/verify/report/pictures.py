"""Pictures of the robot as each engine sees it: the source model, MuJoCo and PyBullet, at the same
configurations through the same camera, side by side in the report, so that a flipped wheel, a shape
in the wrong place or a missing mesh shows at a glance.

* **source**: the in-memory model drawn by this module: every shape tessellated
  (:func:`shape_triangles`: boxes, spheres, cylinders, capsules, cones, ellipsoids, meshes read with
  the project's mesh loader), placed by ``Robot.world_poses`` and rasterised with a z-buffer in numpy
  (:func:`rasterize`), so the source needs no renderer at all;
* **mujoco**: the written MJCF in MuJoCo's offscreen renderer (``mujoco.Renderer``) in a child
  process, because MuJoCo picks its OpenGL back end when it is imported (``MUJOCO_GL``): the child
  gets ``MUJOCO_GL=egl`` (or the user's value; ``osmesa`` is tried next), and a machine without
  either gets a note, never a failure;
* **pybullet**: the written URDF in PyBullet's TinyRenderer (``getCameraImage`` with
  ``ER_TINY_RENDERER``: software, no GPU or display) in the engine's child worker
  (``engine_pybullet.render``).

Two views: ``visual`` (the shapes a person sees: URDF ``<visual>``, MuJoCo geoms that do not
collide) and ``collision`` (the contact shapes: URDF ``<collision>``, colliding MuJoCo geoms), the
latter in one flat colour everywhere. The camera is the same pinhole in all three (eye, target,
up, vertical field of view 45°, OpenGL projection), so the silhouettes can be compared pixel for
pixel: each renderer also gives the object mask (MuJoCo's segmentation rendering, PyBullet's
segmentation buffer, the rasteriser's coverage), and the report shows, per engine, the pixels where
its silhouette differs from the source's (:func:`difference`). The robot is drawn as layers 1–3 see
it: root welded at the identity.
"""

from __future__ import annotations

import math
import os
import pickle
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from modelkit.model import Box, Capsule, Cone, Cylinder, Ellipsoid, Geom, Mesh, Robot, Sphere
from modelkit.verify.oneshot import Child, serve

Array = NDArray[np.float64]
Image = NDArray[np.uint8]
Renames = dict[str, dict[str, str]]

KINDS = ("visual", "collision")
ENGINES = ("source", "mujoco", "pybullet")
WIDTH, HEIGHT = 320, 240
FOVY = 45.0  # degrees, vertical (MuJoCo's default; given to PyBullet and the rasteriser)
NEAR, FAR = 0.01, 100.0
VISUAL_GREY = (0.7, 0.7, 0.7)
COLLISION_RGB = (0.90, 0.55, 0.20)  # every collision shape, in every renderer
BACKGROUND = 255
SEGMENTS = 32  # around a cylinder, cone, sphere
CHILD_TIMEOUT = 60.0


# ---- camera ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Camera:
    """A pinhole camera looking from ``eye`` at ``target``, world ``up`` (no roll), vertical field of
    view ``fovy`` degrees, an image of ``width`` × ``height`` pixels."""

    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    fovy: float = FOVY
    width: int = WIDTH
    height: int = HEIGHT

    def view(self) -> Array:
        """World → camera (OpenGL: the camera looks along its −z)."""
        eye, target = np.asarray(self.eye, dtype=float), np.asarray(self.target, dtype=float)
        forward = (target - eye) / np.linalg.norm(target - eye)
        right = np.cross(forward, np.asarray(self.up, dtype=float))
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        m = np.eye(4)
        m[0, :3], m[1, :3], m[2, :3] = right, up, -forward
        m[:3, 3] = -m[:3, :3] @ eye
        return m

    def projection(self) -> Array:
        f = 1.0 / math.tan(math.radians(self.fovy) / 2.0)
        aspect = self.width / self.height
        return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                         [0, 0, (FAR + NEAR) / (NEAR - FAR), 2 * FAR * NEAR / (NEAR - FAR)], [0, 0, -1, 0]])

    def mujoco(self) -> dict[str, Any]:
        """MuJoCo's free camera (``mjvCamera``) with the same eye and target."""
        eye, target = np.asarray(self.eye, dtype=float), np.asarray(self.target, dtype=float)
        d = float(np.linalg.norm(target - eye))
        f = (target - eye) / d
        return {"lookat": [float(v) for v in target], "distance": d,
                "azimuth": math.degrees(math.atan2(f[1], f[0])), "elevation": math.degrees(math.asin(f[2]))}

    def as_dict(self) -> dict[str, Any]:
        return {"eye": list(self.eye), "target": list(self.target), "up": list(self.up), "fovy": self.fovy,
                "width": self.width, "height": self.height, "near": NEAR, "far": FAR}


def frame_camera(points: Array, width: int = WIDTH, height: int = HEIGHT, azimuth: float = -140.0,
                 elevation: float = -25.0, fill: float = 0.85) -> Camera:
    """A camera from the front left, above, looking at the centre of ``points`` (n, 3: the robot at
    q = 0), moved along its line of sight until the points fill ``fill`` of the image's half-width or
    half-height (a few projections: perspective is not linear in the distance)."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = (lo + hi) / 2.0
    radius = max(float(np.linalg.norm(hi - lo)) / 2.0, 1e-3)
    az, el = math.radians(azimuth), math.radians(elevation)
    forward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    distance = 3.0 * radius
    camera = Camera((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    for _ in range(4):
        eye = centre - distance * forward
        camera = Camera((float(eye[0]), float(eye[1]), float(eye[2])),
                        (float(centre[0]), float(centre[1]), float(centre[2])), width=width, height=height)
        homo = np.concatenate([points, np.ones((len(points), 1))], axis=1) @ (camera.projection()
                                                                              @ camera.view()).T
        extent = float(np.max(np.abs(homo[:, :2] / homo[:, 3:4])))
        depth = float(np.min(homo[:, 3]))  # nearest point's distance along the view axis
        # Moving by Δ scales the apparent size by about (depth / (depth + Δ)) for the nearest points.
        new = distance + depth * (extent / fill - 1.0)
        distance = max(new, distance - 0.9 * depth, radius * 1.05)
    return camera


# ---- tessellation ---------------------------------------------------------------------------------


def _lathe(profile: list[tuple[float, float]], n: int = SEGMENTS) -> tuple[Array, NDArray[np.int64]]:
    """A surface of revolution about Z from (radius, z) points (triangles at radius 0 are degenerate,
    which the rasteriser ignores)."""
    angles = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    rho = np.array([p[0] for p in profile])
    z = np.array([p[1] for p in profile])
    vertices = np.stack([np.outer(rho, np.cos(angles)), np.outer(rho, np.sin(angles)),
                         np.repeat(z[:, None], n, axis=1)], axis=-1).reshape(-1, 3)
    faces = []
    for i in range(len(profile) - 1):
        for j in range(n):
            a, b = i * n + j, i * n + (j + 1) % n
            c, d = a + n, b + n
            faces += [(a, b, d), (a, d, c)]
    return vertices, np.array(faces, dtype=np.int64)


def _arc(radius: float, z0: float, start: float, stop: float, steps: int) -> list[tuple[float, float]]:
    return [(radius * math.sin(t), z0 - radius * math.cos(t)) for t in np.linspace(start, stop, steps)]


def shape_triangles(geom: Geom) -> tuple[Array, NDArray[np.int64]] | str:
    """The shape's triangles in its link frame (``geom.pose`` applied), or why it cannot be drawn."""
    g = geom.geometry
    if isinstance(g, Box):
        s = np.asarray(g.size, dtype=float) / 2.0
        v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float) * s
        f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], dtype=np.int64)
    elif isinstance(g, Sphere):
        v, f = _lathe(_arc(g.radius, 0.0, 0.0, math.pi, SEGMENTS // 2 + 1))
    elif isinstance(g, Ellipsoid):
        v, f = _lathe(_arc(1.0, 0.0, 0.0, math.pi, SEGMENTS // 2 + 1))
        v = v * np.asarray(g.radii, dtype=float)
    elif isinstance(g, Cylinder):
        h = g.length / 2.0
        v, f = _lathe([(0.0, -h), (g.radius, -h), (g.radius, h), (0.0, h)])
    elif isinstance(g, Cone):
        h = g.length / 2.0
        v, f = _lathe([(0.0, -h), (g.radius, -h), (0.0, h)])
    elif isinstance(g, Capsule):
        h, q = g.length / 2.0, SEGMENTS // 4 + 1
        v, f = _lathe(_arc(g.radius, -h, 0.0, math.pi / 2, q) + _arc(g.radius, h, math.pi / 2, math.pi, q))
    elif isinstance(g, Mesh):
        loaded = _mesh_triangles(g)
        if isinstance(loaded, str):
            return loaded
        v, f = loaded
    else:
        return f"{type(g).__name__} cannot be drawn"
    return v @ geom.pose.rotation.T + geom.pose.translation, f


_MESHES: dict[tuple[str, str | None, str], tuple[Array, NDArray[np.int64]] | str] = {}


def _mesh_triangles(g: Mesh) -> tuple[Array, NDArray[np.int64]] | str:
    """A mesh's triangles (scaled); files read once per process (both wheels share one file)."""
    scale = np.asarray(g.scale, dtype=float)
    if g.data is None and g.path is not None:
        key = (str(g.path), g.fragment, repr(g.source_params.get("metadata")))
        if key not in _MESHES:
            _MESHES[key] = _mesh_file(g)
        found = _MESHES[key]
        return found if isinstance(found, str) else (found[0] * scale, found[1])
    return _mesh_file(g) if g.data is None else (np.asarray(g.data.vertices, dtype=float) * scale,
                                                   np.asarray(g.data.faces, dtype=np.int64))


def _mesh_file(g: Mesh) -> tuple[Array, NDArray[np.int64]] | str:
    """The file's triangles, unscaled, or why they cannot be had."""
    scale = np.ones(3)
    if g.data is not None:
        return np.asarray(g.data.vertices, dtype=float) * scale, np.asarray(g.data.faces, dtype=np.int64)
    if g.path is None or not os.path.isfile(g.path):
        return f"mesh {g.uri or g.path or '(no uri)'} not found"
    from modelkit.geometry.meshfiles import MeshLoadError, MeshMetadata, load_mesh

    meta = g.source_params.get("metadata")
    metadata = (MeshMetadata(meta.get("length_unit"), meta.get("upper_axis"))
                if isinstance(meta, dict) and meta else None)
    try:
        loaded = load_mesh(Path(g.path), g.fragment, metadata)
    except MeshLoadError as exc:
        return f"mesh {g.uri or g.path} cannot be loaded ({exc.message})"
    faces = np.asarray(loaded.mesh.faces, dtype=np.int64)
    return np.asarray(loaded.mesh.vertices, dtype=float) * scale, faces


class SourceScene:
    """The source model's shapes, tessellated once, posed per configuration."""

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.notes: list[str] = []
        # kind → [(link, vertices in the link frame, faces, rgb)]
        self.shapes: dict[str, list[tuple[str, Array, NDArray[np.int64], tuple[float, float, float]]]] = {
            k: [] for k in KINDS}
        for link in robot.links:
            for kind in KINDS:
                for geom in link.visuals if kind == "visual" else link.collisions:
                    tri = shape_triangles(geom)
                    if isinstance(tri, str):
                        self.notes.append(f"source {kind} of link {link.name}: {tri} (not drawn)")
                        continue
                    rgb: tuple[float, float, float] = COLLISION_RGB
                    if kind == "visual":
                        rgba = geom.material.rgba if geom.material is not None else None
                        rgb = rgba[:3] if rgba is not None else VISUAL_GREY
                    self.shapes[kind].append((link.name, tri[0], tri[1], rgb))

    def triangles(self, kind: str, q: dict[str, float]) -> tuple[Array, Array]:
        """(T, 3, 3) world triangles and (T, 3) colours at configuration ``q``."""
        poses = self.robot.world_poses(q)
        tris, colours = [], []
        for link, v, f, rgb in self.shapes[kind]:
            pose = poses.get(link)
            if pose is None or len(f) == 0:
                continue
            world = v @ pose.rotation.T + pose.translation
            tris.append(world[f])
            colours.append(np.tile(np.asarray(rgb, dtype=float), (len(f), 1)))
        if not tris:
            return np.zeros((0, 3, 3)), np.zeros((0, 3))
        return np.concatenate(tris), np.concatenate(colours)

    def points(self) -> Array:
        """Every vertex of every shape at q = 0 (for framing the camera)."""
        pts = [self.triangles(kind, {})[0].reshape(-1, 3) for kind in KINDS]
        allpts = np.concatenate(pts) if pts else np.zeros((0, 3))
        if len(allpts) == 0:
            origins = [p.translation for p in self.robot.world_poses().values()]
            allpts = np.array(origins) if origins else np.zeros((1, 3))
        return allpts


# ---- rasteriser -----------------------------------------------------------------------------------


def rasterize(tris: Array, colours: Array, camera: Camera) -> tuple[Image, NDArray[np.bool_]]:
    """Flat-shaded, z-buffered triangles (headlight, two-sided) → (H, W, 3) image on white and the
    (H, W) coverage mask. Pixel centres at (i + 0.5); vectorised in batches of similar-size
    triangles."""
    w, h = camera.width, camera.height
    image = np.full((h, w, 3), BACKGROUND, dtype=np.uint8)
    mask = np.zeros((h, w), dtype=bool)
    if len(tris) == 0:
        return image, mask
    mvp = camera.projection() @ camera.view()
    homo = np.concatenate([tris, np.ones((*tris.shape[:2], 1))], axis=2) @ mvp.T  # (T, 3, 4)
    keep = np.all(homo[:, :, 3] > NEAR, axis=1)
    homo, tris, colours = homo[keep], tris[keep], colours[keep]
    ndc = homo[:, :, :3] / homo[:, :, 3:4]
    sx = (ndc[:, :, 0] + 1.0) * 0.5 * w
    sy = (1.0 - ndc[:, :, 1]) * 0.5 * h
    sz = ndc[:, :, 2]
    # Shading: |cos| between the face normal and the viewing direction (a headlight, as MuJoCo's).
    normal = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    norm = np.linalg.norm(normal, axis=1)
    ok = norm > 0
    view_dir = np.asarray(camera.target, dtype=float) - np.asarray(camera.eye, dtype=float)
    view_dir /= np.linalg.norm(view_dir)
    shade = np.zeros(len(tris))
    shade[ok] = np.abs(normal[ok] @ view_dir) / norm[ok]
    rgb = np.clip(colours * (0.35 + 0.65 * shade)[:, None], 0.0, 1.0)
    area = (sx[:, 1] - sx[:, 0]) * (sy[:, 2] - sy[:, 0]) - (sx[:, 2] - sx[:, 0]) * (sy[:, 1] - sy[:, 0])
    x0 = np.clip(np.floor(sx.min(axis=1) - 0.5).astype(int) + 1, 0, w)
    x1 = np.clip(np.floor(sx.max(axis=1) - 0.5).astype(int), -1, w - 1)
    y0 = np.clip(np.floor(sy.min(axis=1) - 0.5).astype(int) + 1, 0, h)
    y1 = np.clip(np.floor(sy.max(axis=1) - 0.5).astype(int), -1, h - 1)
    size = np.maximum(x1 - x0 + 1, y1 - y0 + 1)
    live = (np.abs(area) > 1e-12) & (x1 >= x0) & (y1 >= y0)
    flat_all, depth_all, tri_all = [], [], []
    k = 1
    while True:
        group = np.nonzero(live & (size <= k) & (size > k // 2))[0]
        chunk = max(1, 2_000_000 // (k * k))
        for s in range(0, len(group), chunk):
            idx = group[s:s + chunk]
            oy, ox = np.mgrid[0:k, 0:k]
            px = x0[idx, None, None] + ox[None]
            py = y0[idx, None, None] + oy[None]
            cx, cy = px + 0.5, py + 0.5
            ax, ay, bx, by, qx, qy = (sx[idx, 0, None, None], sy[idx, 0, None, None], sx[idx, 1, None, None],
                                      sy[idx, 1, None, None], sx[idx, 2, None, None], sy[idx, 2, None, None])
            a = area[idx, None, None]
            w0 = ((bx - cx) * (qy - cy) - (qx - cx) * (by - cy)) / a
            w1 = ((qx - cx) * (ay - cy) - (ax - cx) * (qy - cy)) / a
            w2 = 1.0 - w0 - w1
            inside = ((w0 >= 0) & (w1 >= 0) & (w2 >= 0) & (px <= x1[idx, None, None])
                      & (py <= y1[idx, None, None]))
            z = w0 * sz[idx, 0, None, None] + w1 * sz[idx, 1, None, None] + w2 * sz[idx, 2, None, None]
            t, _, _ = np.nonzero(inside)
            flat_all.append((py * w + px)[inside])
            depth_all.append(z[inside])
            tri_all.append(idx[t])
        if k >= max(w, h) or not np.any(live & (size > k)):
            break
        k *= 2
    if not flat_all:
        return image, mask
    flat, depth, tri = np.concatenate(flat_all), np.concatenate(depth_all), np.concatenate(tri_all)
    order = np.lexsort((tri, depth, flat))  # nearest first per pixel; ties by triangle: deterministic
    flat, tri = flat[order], tri[order]
    first = np.ones(len(flat), dtype=bool)
    first[1:] = flat[1:] != flat[:-1]
    pix, winner = flat[first], tri[first]
    image.reshape(-1, 3)[pix] = np.round(rgb[winner] * 255).astype(np.uint8)
    mask.reshape(-1)[pix] = True
    return image, mask


# ---- results --------------------------------------------------------------------------------------


@dataclass
class Picture:
    engine: str
    kind: str  # "visual" | "collision"
    config: int  # index into PictureSet.configurations
    image: Image  # (H, W, 3), background white
    mask: NDArray[np.bool_]  # (H, W) robot pixels


@dataclass
class PictureSet:
    camera: Camera
    configurations: list[dict[str, float]]
    pictures: list[Picture] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # renderers unavailable, shapes not drawn
    timings: dict[str, float] = field(default_factory=dict)
    settings: dict[str, Any] = field(default_factory=dict)

    def get(self, engine: str, kind: str, config: int) -> Picture | None:
        for p in self.pictures:
            if (p.engine, p.kind, p.config) == (engine, kind, config):
                return p
        return None


def difference(source: NDArray[np.bool_], engine: NDArray[np.bool_]) -> tuple[Image, float]:
    """The silhouette difference as a picture (grey: both; red: only the engine draws it; blue: only
    the source does) and its size: differing pixels / pixels of either silhouette (0 = identical)."""
    img = np.full((*source.shape, 3), BACKGROUND, dtype=np.uint8)
    img[source & engine] = (200, 200, 200)
    img[engine & ~source] = (220, 30, 30)
    img[source & ~engine] = (30, 60, 220)
    union = int(np.count_nonzero(source | engine))
    return img, (float(np.count_nonzero(source ^ engine)) / union if union else 0.0)


def _compose(rgb: Image, mask: NDArray[np.bool_]) -> Image:
    out = np.full(rgb.shape, BACKGROUND, dtype=np.uint8)
    out[mask] = rgb[mask]
    return out


# ---- MuJoCo (child process) -----------------------------------------------------------------------


def _mujoco_request(mjcf: Path, joints: list[dict[str, float]], camera: Camera) -> dict[str, Any]:
    return {"path": str(Path(mjcf).resolve()), "configurations": joints, "camera": camera.as_dict(),
            "mujoco_camera": camera.mujoco(), "collision_rgb": COLLISION_RGB}


def _mujoco_render(request: dict[str, Any]) -> dict[str, Any]:
    """In the child: every configuration × view, RGB and segmentation."""
    import mujoco

    from modelkit.formats.mjcf.quiet import collected_warnings

    cam = request["camera"]
    with collected_warnings(mujoco) as warnings:
        model = mujoco.MjModel.from_xml_path(request["path"])
        model.vis.global_.fovy = cam["fovy"]
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, cam["width"])
        model.vis.global_.offheight = max(model.vis.global_.offheight, cam["height"])
        data = mujoco.MjData(model)
        collides = (model.geom_contype | model.geom_conaffinity) != 0
        visual = ~collides if np.any(~collides) else np.ones(model.ngeom, dtype=bool)
        group0, rgba0 = model.geom_group.copy(), model.geom_rgba.copy()
        renderer = mujoco.Renderer(model, cam["height"], cam["width"])
        camera = mujoco.MjvCamera()
        camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        mc = request["mujoco_camera"]
        camera.lookat[:] = mc["lookat"]
        camera.distance, camera.azimuth, camera.elevation = mc["distance"], mc["azimuth"], mc["elevation"]
        model.vis.headlight.ambient[:] = (0.35, 0.35, 0.35)  # the rasteriser's 0.35 + 0.65·|cos|
        model.vis.headlight.diffuse[:] = (0.65, 0.65, 0.65)
        model.vis.headlight.specular[:] = (0.0, 0.0, 0.0)
        option = mujoco.MjvOption()
        option.geomgroup[:] = 0
        option.geomgroup[0] = 1
        out = []
        for index, q in enumerate(request["configurations"]):
            data.qpos[:] = model.qpos0
            for name, value in q.items():
                jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
                if jid >= 0:
                    data.qpos[model.jnt_qposadr[jid]] = value
            mujoco.mj_kinematics(model, data)
            for kind, shown in (("visual", visual), ("collision", collides)):
                model.geom_group[:] = np.where(shown, 0, 5)
                model.geom_rgba[:] = rgba0
                if kind == "collision":
                    model.geom_rgba[:, :3] = request["collision_rgb"]
                    model.geom_rgba[:, 3] = 1.0
                renderer.disable_segmentation_rendering()
                renderer.update_scene(data, camera, option)
                rgb = renderer.render().copy()
                renderer.enable_segmentation_rendering()
                renderer.update_scene(data, camera, option)
                seg = renderer.render()[:, :, 0].copy()
                out.append({"kind": kind, "config": index, "rgb": rgb.tobytes(),
                            "mask": (seg >= 0).tobytes()})
        model.geom_group[:], model.geom_rgba[:] = group0, rgba0
        renderer.close()
    return {"images": out, "warnings": list(warnings), "gl": os.environ.get("MUJOCO_GL", ""),
            "version": mujoco.__version__}


def mujoco_child() -> int:
    """The child's entry point (:func:`modelkit.verify.oneshot.serve`): a render request in, the
    images out."""
    return serve(_mujoco_render)


def _gl_backends() -> list[str]:
    chosen = os.environ.get("MUJOCO_GL", "").strip().lower()
    return [chosen] if chosen else ["egl", "osmesa"]


class _MujocoJob:
    """The MuJoCo child, started at once so that it renders while the parent draws the source."""

    def __init__(self, mjcf: Path, joints: list[dict[str, float]], camera: Camera) -> None:
        self.request = _mujoco_request(mjcf, joints, camera)
        self.backends = _gl_backends()
        self.tried: list[str] = []
        self._tmp = tempfile.TemporaryDirectory(prefix="modelkit-mjrender-")
        self._start()

    def _start(self) -> None:
        gl = self.backends.pop(0)
        code = ("import sys; from modelkit.verify.report.pictures import mujoco_child; "
                "sys.exit(mujoco_child())")
        self.gl = gl
        # cwd: a temporary folder, so that nothing MuJoCo might write lands in the user's folder.
        self.child = Child(code, env=dict(os.environ, MUJOCO_GL=gl, PYOPENGL_PLATFORM=gl), cwd=self._tmp.name)
        self.child.send(self.request)

    def result(self) -> tuple[dict[str, Any] | None, str]:
        """(result, "") or (None, why MuJoCo could not render)."""
        try:
            while True:
                status, value = self.child.reply(CHILD_TIMEOUT)
                if status == "ok":
                    return value, ""
                self.tried.append(f"MUJOCO_GL={self.gl}: {value}")
                if not self.backends:
                    return None, "; ".join(self.tried)
                self._start()
        finally:
            self._tmp.cleanup()


# ---- PyBullet -------------------------------------------------------------------------------------


def collision_urdf(urdf: Path, out: Path) -> Path:
    """A copy of ``urdf`` whose visuals are its collision shapes (one flat colour), mesh file names
    made absolute so that the copy can live elsewhere: what TinyRenderer draws of it is PyBullet's
    view of the contact geometry."""
    from lxml import etree

    tree = etree.parse(str(urdf))
    base = urdf.resolve().parent
    for mesh in tree.iter("mesh"):
        name = mesh.get("filename", "")
        if name and "://" not in name and not os.path.isabs(name):
            mesh.set("filename", str(base / name))
    r, g, b = COLLISION_RGB
    for link in tree.iter("link"):
        for visual in link.findall("visual"):
            link.remove(visual)
        for collision in link.findall("collision"):
            visual = etree.SubElement(link, "visual")
            for child in collision:
                if child.tag in ("origin", "geometry"):
                    visual.append(etree.fromstring(etree.tostring(child)))
            material = etree.SubElement(visual, "material", name="modelkit_collision")
            etree.SubElement(material, "color", rgba=f"{r} {g} {b} 1")
    tree.write(str(out))
    return out


def _pybullet_pictures(urdf: Path, joints: list[dict[str, float]], camera: Camera,
                       pictures: PictureSet) -> None:
    from modelkit.verify.engines import pybullet as engine_pybullet

    with tempfile.TemporaryDirectory(prefix="modelkit-pbrender-") as tmp:
        collision = collision_urdf(urdf, Path(tmp) / "collision.urdf")
        views = engine_pybullet.render({"visual": urdf, "collision": collision}, joints, camera.as_dict())
    for (kind, index), (rgb, mask) in sorted(views.items()):
        pictures.pictures.append(Picture("pybullet", kind, index, _compose(rgb, mask), mask))
    from lxml import etree

    bare = [link.get("name", "") for link in etree.parse(str(urdf)).iter("link")
            if link.find("visual") is None and link.find("collision") is not None]
    if bare:
        pictures.notes.append(
            "pybullet: PyBullet draws a link's collision shapes when the URDF gives it no visual, so its "
            f"visual pictures show them for {', '.join(sorted(bare))} (the others draw nothing there)")


# ---- entry point ----------------------------------------------------------------------------------


def render_pictures(robot: Robot, files: dict[str, Path], renames: dict[str, Renames],
                    configurations: list[dict[str, float]], engines: tuple[str, ...] = ("mujoco", "pybullet"),
                    width: int = WIDTH, height: int = HEIGHT) -> PictureSet:
    """Every engine's pictures of ``robot`` (root welded at the identity) at ``configurations``
    (source joint names). ``files``: "mjcf", "urdf" → the written files; ``renames``: each file's
    renames. A renderer that is unavailable or fails adds a note; it never raises."""
    t0 = time.perf_counter()
    scene = SourceScene(robot)
    camera = frame_camera(scene.points(), width, height)
    pictures = PictureSet(camera, [dict(q) for q in configurations], notes=list(scene.notes))
    pictures.settings = {"camera": camera.as_dict(), "source": "numpy z-buffer rasteriser (modelkit)"}

    def written(fmt: str) -> list[dict[str, float]]:
        names = renames.get(fmt, {}).get("joint", {})
        return [{names.get(j, j): v for j, v in q.items()} for q in configurations]

    job = None
    if "mujoco" in engines:
        if files.get("mjcf") is None or not Path(files["mjcf"]).is_file():
            pictures.notes.append("mujoco: no MJCF file to render")
        else:
            job = _MujocoJob(Path(files["mjcf"]), written("mjcf"), camera)
    t1 = time.perf_counter()
    for index, q in enumerate(configurations):
        for kind in KINDS:
            tris, colours = scene.triangles(kind, q)
            image, mask = rasterize(tris, colours, camera)
            pictures.pictures.append(Picture("source", kind, index, image, mask))
    pictures.timings["source"] = time.perf_counter() - t1
    if "pybullet" in engines:
        t2 = time.perf_counter()
        if files.get("urdf") is None or not Path(files["urdf"]).is_file():
            pictures.notes.append("pybullet: no URDF file to render")
        else:
            try:
                _pybullet_pictures(Path(files["urdf"]), written("urdf"), camera, pictures)
                pictures.settings["pybullet"] = "getCameraImage, ER_TINY_RENDERER, child process"
            except Exception as exc:
                pictures.notes.append(f"pybullet: TinyRenderer could not render: {type(exc).__name__}: {exc}")
        pictures.timings["pybullet"] = time.perf_counter() - t2
    if job is not None:
        t3 = time.perf_counter()
        result, why = job.result()
        if result is None:
            pictures.notes.append(
                "mujoco: its offscreen renderer is not available on this machine (" + why + "); it needs "
                "EGL (Debian: libegl1 libegl-mesa0 libgl1-mesa-dri) or OSMesa (libosmesa6)")
        else:
            for item in result["images"]:
                rgb = np.frombuffer(item["rgb"], dtype=np.uint8).reshape(height, width, 3)
                mask = np.frombuffer(item["mask"], dtype=bool).reshape(height, width)
                pictures.pictures.append(Picture("mujoco", item["kind"], item["config"], _compose(rgb, mask),
                                                 mask.copy()))
            pictures.settings["mujoco"] = (f"mujoco.Renderer {result['version']}, MUJOCO_GL={result['gl']}, "
                                           "child process")
            pictures.notes.extend(f"mujoco warned: {w}" for w in result["warnings"])
        pictures.timings["mujoco (wait)"] = time.perf_counter() - t3
    order = {e: i for i, e in enumerate(ENGINES)}
    pictures.pictures.sort(key=lambda p: (p.config, KINDS.index(p.kind), order.get(p.engine, 9)))
    pictures.timings["total"] = time.perf_counter() - t0
    return pictures


# ---- the whole set in a child process -------------------------------------------------------------
# ``verify`` starts this as soon as the files are written, so that the pictures (the source's
# rasterising in numpy and both engines' children) are made on another core while the layers run,
# and the report only collects them. Any failure of the child falls back to rendering here.

PICTURES_TIMEOUT = 180.0
_PICTURES_CHILD = ("import sys; from modelkit.verify.report.pictures import pictures_child; "
                   "sys.exit(pictures_child())")


def pictures_child() -> int:
    """The child's entry point (:func:`modelkit.verify.oneshot.serve`): :func:`render_pictures`'s
    arguments in, the PictureSet out."""
    return serve(lambda args: render_pictures(*args))


class PictureJob:
    """:func:`render_pictures` in a child process, started at once; :meth:`result` waits for it (and
    renders here when the child failed), :meth:`close` ends it unasked."""

    def __init__(self, robot: Robot, files: dict[str, Path], renames: dict[str, Renames],
                 configurations: list[dict[str, float]], engines: tuple[str, ...] = ("mujoco", "pybullet")
                 ) -> None:
        self.args = (robot, {k: Path(v).resolve() for k, v in files.items()}, renames,
                     [dict(q) for q in configurations], tuple(engines))
        self.child: Child | None = None
        try:
            self.child = Child(_PICTURES_CHILD)
            self.child.send(self.args)
        except (OSError, ValueError, pickle.PicklingError):
            self.close()

    def result(self) -> PictureSet:
        child, self.child = self.child, None
        if child is not None:
            status, value = child.reply(PICTURES_TIMEOUT)
            if status == "ok" and isinstance(value, PictureSet):
                return value
        return render_pictures(*self.args)

    def close(self) -> None:
        child, self.child = self.child, None
        if child is not None:
            child.end()
