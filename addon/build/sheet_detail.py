"""How finely Blender tessellates a streak surface, from the scene's camera ([Smoke Surfaces]
§3.3, Figure 7: a NURBS sheet, unlike a bitmap or a volume, stays smooth as the camera comes
close). Blender draws a NURBS surface as a grid of nu·resolution_u × nv·resolution_v samples,
evenly spread over the knot domain; a fixed resolution shows straight facets once a knot span
fills a good part of the frame. The frame handler sets, on every frame, the resolution that makes
every tessellated edge of the sheet's visible part at most PIXELS_PER_EDGE pixels long at the
render's size (resolution × percentage).

The speed of a B-spline is bounded by its control polygon (|C'| ≤ max (k - 1)|P_{i+1} - P_i| /
(t_{i+k} - t_{i+1})), so an edge is at most that speed (in pixels, on the projected net) times
the parameter step between samples, (nu - k + 1) / (nu·r - 1) along u (likewise along v). The
projection is the camera's own (view_frame: sensor fit, shift,
perspective or orthographic), applied to the control points in NumPy: a handful of matrix
products per surface, cheap enough for every frame and every motion-blur sub-frame."""

import math

import numpy as np

#: Longest tessellated edge wanted on screen, in pixels of the rendered image. A chord of length
#: L on a curve of radius R (pixels) leaves a gap L²/8R from it: at 8 px that is under half a
#: pixel down to curls of 16 px radius, and the turn between consecutive edges (L/R radians) stays
#: a few degrees on the sheet's broad folds, where a facet would show as a change of shading.
PIXELS_PER_EDGE = 8.0
#: Most vertices (samples u × v) one sheet is tessellated into. Blender spreads the samples
#: evenly over the whole sheet, so in a close-up the parts outside the frame take most of them:
#: the newcomer's sheets seen from 0.6 m at 1920 × 1080 (the manual's close-up) want up to
#: 400,000 for 8 px, and from 0.35 m up to 4.6 million. 262,144 (512²: some 30 MB of mesh per
#: sheet in Blender) makes the edges of the first a quarter longer at most, and of the second
#: about twice, still with no visible turn between them.
MAX_VERTICES = 262_144
#: Blender's range of Spline.resolution_u / resolution_v.
RESOLUTION_MAX = 1024
#: Control points this far outside the frame (as a share of its width / height) still count as
#: visible: a leg from a point just off-screen crosses the picture.
MARGIN = 0.5


def camera_pixels(scene, points):
    """Pixel coordinates (n, 2) of world points (n, 3) in the render of scene.camera, and a mask
    of the points in front of the camera within the frame plus MARGIN; None without a camera."""
    cam = scene.camera
    if cam is None or cam.type != 'CAMERA':
        return None
    r = scene.render
    width = r.resolution_x * r.resolution_percentage / 100.0
    height = r.resolution_y * r.resolution_percentage / 100.0
    frame = [tuple(v) for v in cam.data.view_frame(scene=scene)]
    xs, ys = [v[0] for v in frame], [v[1] for v in frame]
    depth = -frame[0][2]  # the frame's corners lie at one depth in camera space
    to_cam = np.array(cam.matrix_world.inverted(), dtype=np.float64)
    local = points @ to_cam[:3, :3].T + to_cam[:3, 3]
    z = -local[:, 2]
    if cam.data.type == 'ORTHO':
        front = np.ones(len(points), dtype=bool)
        scale = np.ones(len(points))
    else:
        front = z > 1e-6 * max(depth, 1e-9)
        scale = depth / np.where(front, z, 1.0)
    x = (local[:, 0] * scale - min(xs)) / (max(xs) - min(xs))
    y = (local[:, 1] * scale - min(ys)) / (max(ys) - min(ys))
    inside = front & (x > -MARGIN) & (x < 1 + MARGIN) & (y > -MARGIN) & (y < 1 + MARGIN)
    return np.stack([x * width, y * height], axis=1), inside


def fastest_speed(px, inside, axis, order):
    """Largest speed |C'(t)| (pixels per unit of Blender's knot parameter) along axis (1: u,
    0: v) of the projected net (nv, nu, 2), over the legs with an end in view; 0 when none is.
    C' = Σ Q_i N_{i,k-1} with Q_i = (k - 1)(P_{i+1} - P_i) / (t_{i+k} - t_{i+1}) on Blender's
    endpoint knots, and the N partition unity: |C'| ≤ max |Q_i| (the clamped end legs count up
    to k - 1 times their length)."""
    n = px.shape[axis]
    if n < 2:
        return 0.0
    legs = np.linalg.norm(np.diff(px, axis=axis), axis=-1)
    a = np.take(inside, range(n - 1), axis=axis)
    b = np.take(inside, range(1, n), axis=axis)
    p = order - 1
    knots = np.concatenate([np.zeros(order), np.arange(1, n - order + 1), np.full(order, n - order + 1)])
    span = knots[np.arange(1, n) + p] - knots[np.arange(1, n)]  # t_{i+k} - t_{i+1}, i < n - 1
    scale = p / np.maximum(span, 1e-9)
    speed = legs * (scale[None, :] if axis == 1 else scale[:, None])
    seen = speed[a | b]
    return float(seen.max()) if seen.size else 0.0


def samples_per_point(speed, count, order):
    """resolution (samples per control point) whose samples, evenly spread over the knot domain
    (count - order + 1 units: count * resolution - 1 steps), are at most PIXELS_PER_EDGE apart at
    `speed`; an order-2 direction keeps 1 (its samples are its control points: the straight net
    is drawn exactly)."""
    if order <= 2 or speed <= 0.0:
        return 1
    steps = speed * (count - order + 1) / PIXELS_PER_EDGE
    return max(1, math.ceil((steps + 1) / count))


def resolutions(scene, world_points, nu, nv, order_u, order_v, max_vertices=MAX_VERTICES):
    """(resolution_u, resolution_v) for a net of world points (nv * nu, 3) in Blender's flat
    order, or None without a camera or with no visible control point. Where they would make more
    than max_vertices samples, both are cut by the same factor (edges that much longer)."""
    hit = camera_pixels(scene, world_points)
    if hit is None or not hit[1].any():
        return None
    px, inside = hit[0].reshape(nv, nu, 2), hit[1].reshape(nv, nu)
    ru = samples_per_point(fastest_speed(px, inside, 1, min(order_u, nu)), nu, min(order_u, nu))
    rv = samples_per_point(fastest_speed(px, inside, 0, min(order_v, nv)), nv, min(order_v, nv))
    ru, rv = min(ru, RESOLUTION_MAX), min(rv, RESOLUTION_MAX)
    over = (nu * ru) * (nv * rv) / max_vertices
    if over > 1.0:  # both directions coarsened alike, as the budget allows
        shrink = math.sqrt(over)
        ru = max(1, int(ru / shrink))
        rv = max(1, int(rv / shrink))
    return ru, rv


def update(ob, scene, default):
    """Sets the surface's resolution_u / resolution_v from the scene's camera (default (u, v)
    without one); True when they changed."""
    sp = ob.data.splines[0]
    nu, nv = sp.point_count_u, sp.point_count_v
    co = np.empty(len(sp.points) * 4, dtype=np.float32)
    sp.points.foreach_get("co", co)
    local = co.reshape(-1, 4)[:, :3].astype(np.float64)
    m = np.array(ob.matrix_world, dtype=np.float64)
    world = local @ m[:3, :3].T + m[:3, 3]
    res = resolutions(scene, world, nu, nv, sp.order_u, sp.order_v)
    if res is None:
        res = default(sp.order_u, sp.order_v)
    if (sp.resolution_u, sp.resolution_v) == res:
        return False
    sp.resolution_u, sp.resolution_v = res
    return True
