"""Hull geometry of the tow and its surroundings, shared by the closed-loop master's map and
the acceptance tests' overlap checks.

Frames as in docs/interface.md: NED, x North, y East (m), heading psi from North, clockwise
positive. Every function works on whole time series at once (numpy arrays of shape (T,) for
poses, (T, n, 2) for polygons), so a 12000-row run is checked in milliseconds.

Shapes (real size):
- a tow vessel is the rectangle of its `length` x `width`, spanning body x from its stern
  towing point to its bow towing point (both from the scenario's vessel data; for CyberShip II
  they are -0.624 m and 0.631 m from the body origin, exactly the 1.255 m hull; for the
  TitoNeri -0.5 m and 0.5 m, so the 0.97 m hull is centred on the origin);
- a static hazard is a circle of diameter `length` (= `width`);
- a target ship is an ellipse with major axis `length` along its course `psi` and minor axis
  `width`. Overlap checks use a polygon circumscribing the ellipse (conservative: it contains
  the ellipse and is at most 1/cos(pi/n) - 1 = 0.05 % larger for n = 96).
"""

import math
import pathlib
import tomllib

import numpy as np

# Vessel presets (crates/towing-model, VesselData::cybership2 / ::titoneri;
# docs/scenario-format.md, "Vessel data"). A scenario's [vessels.<v>] table overrides them.
PRESETS = {
    "ship": {"length": 1.255, "width": 0.29, "stern_tow_point_x": -0.624, "bow_tow_point_x": 0.631},
    "tug1": {"length": 0.97, "width": 0.30, "stern_tow_point_x": -0.5, "bow_tow_point_x": 0.5},
    "tug2": {"length": 0.97, "width": 0.30, "stern_tow_point_x": -0.5, "bow_tow_point_x": 0.5},
}
VESSELS = ("ship", "tug1", "tug2")
ELLIPSE_SEGMENTS = 96


def load_scenario(path):
    """The scenario TOML as a dict (tomllib; the plant validates it, this only reads it)."""
    with open(path, "rb") as f:
        return tomllib.load(f)


def vessel_dims(scenario):
    """{vessel: {length, width, centre}}: hull size and the body-x offset of the hull centre."""
    dims = {}
    overrides = (scenario or {}).get("vessels", {})
    for name in VESSELS:
        d = dict(PRESETS[name])
        d.update({k: v for k, v in overrides.get(name, {}).items() if k in d})
        # The hull is centred between the towing points when they bound the hull (the presets);
        # otherwise (a user moved them) keep the hull centred between them anyway: the towing
        # points are the only fore-aft reference the scenario gives.
        d["centre"] = 0.5 * (d["stern_tow_point_x"] + d["bow_tow_point_x"])
        dims[name] = d
    return dims


def route_points(scenario):
    """Route as an array of (x, y, psi) rows: origin, waypoints, destination."""
    route = scenario["route"]
    pts = [route["origin"], *route["waypoints"], route["destination"]]
    return np.array([[p["x"], p["y"], math.radians(p["psi_deg"])] for p in pts])


def rectangle(x, y, psi, length, width, centre=0.0):
    """Corners (T, 4, 2) in (North, East) of rectangles of a body at poses (x, y, psi)."""
    x, y, psi = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (x, y, psi))
    body = np.array(
        [[centre + length / 2, width / 2], [centre - length / 2, width / 2], [centre - length / 2, -width / 2], [centre + length / 2, -width / 2]]
    )
    return _place(body, x, y, psi)


def hull_outline(x, y, psi, length, width, centre=0.0):
    """A ship-like outline (pointed bow) for drawing, (T, 5, 2) in (North, East)."""
    x, y, psi = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (x, y, psi))
    h, w = length / 2, width / 2
    body = np.array([[centre + h, 0.0], [centre + h / 2, w], [centre - h, w], [centre - h, -w], [centre + h / 2, -w]])
    return _place(body, x, y, psi)


def ellipse(x, y, psi, length, width, n=ELLIPSE_SEGMENTS, circumscribed=True):
    """Polygon (T, n, 2) of ellipses with major axis `length` along psi, minor axis `width`.

    `circumscribed` scales the vertices by 1/cos(pi/n) so the polygon contains the ellipse
    (an affine image of a regular polygon circumscribing the unit circle)."""
    x, y, psi = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (x, y, psi))
    length = np.broadcast_to(np.asarray(length, dtype=float), x.shape)
    width = np.broadcast_to(np.asarray(width, dtype=float), x.shape)
    k = 1.0 / math.cos(math.pi / n) if circumscribed else 1.0
    a = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    bx = k * np.cos(a)[None, :] * (length[:, None] / 2)
    by = k * np.sin(a)[None, :] * (width[:, None] / 2)
    c, s = np.cos(psi)[:, None], np.sin(psi)[:, None]
    return np.stack([x[:, None] + bx * c - by * s, y[:, None] + bx * s + by * c], axis=-1)


def _place(body, x, y, psi):
    c, s = np.cos(psi)[:, None], np.sin(psi)[:, None]
    bx, by = body[None, :, 0], body[None, :, 1]
    return np.stack([x[:, None] + bx * c - by * s, y[:, None] + bx * s + by * c], axis=-1)


def _edge_normals(poly):
    edges = np.roll(poly, -1, axis=1) - poly
    n = np.stack([-edges[..., 1], edges[..., 0]], axis=-1)
    return n / np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-300)


def polygons_overlap(p, q):
    """Separating-axis test of convex polygons, row by row: p (T, n, 2), q (T, m, 2) -> (T,) bool.

    Touching counts as not overlapping; any positive penetration overlaps."""
    axes = np.concatenate([_edge_normals(p), _edge_normals(q)], axis=1)  # (T, n+m, 2)
    pp = np.einsum("tkd,tid->tki", axes, p)
    qq = np.einsum("tkd,tid->tki", axes, q)
    separated = (pp.max(axis=2) <= qq.min(axis=2)) | (qq.max(axis=2) <= pp.min(axis=2))
    return ~separated.any(axis=1)


def penetration_depth(p, q):
    """Smallest overlap of the projections over the SAT axes (T,), <= 0 when separated."""
    axes = np.concatenate([_edge_normals(p), _edge_normals(q)], axis=1)
    pp = np.einsum("tkd,tid->tki", axes, p)
    qq = np.einsum("tkd,tid->tki", axes, q)
    overlap = np.minimum(pp.max(axis=2), qq.max(axis=2)) - np.maximum(pp.min(axis=2), qq.min(axis=2))
    return overlap.min(axis=1)


def rectangle_circle_gap(corners, cx, cy, radius):
    """Distance from each rectangle (T, 4, 2; corners in order) to each circle, minus the radius:
    (T,), negative when they overlap."""
    centre = corners.mean(axis=1)
    ex = corners[:, 0] - corners[:, 1]  # along the length
    ey = corners[:, 0] - corners[:, 3]  # along the width
    half_l = np.linalg.norm(ex, axis=1) / 2
    half_w = np.linalg.norm(ey, axis=1) / 2
    ux = ex / (2 * half_l)[:, None]
    uy = ey / (2 * half_w)[:, None]
    d = np.stack([np.asarray(cx, dtype=float), np.asarray(cy, dtype=float)], axis=-1) - centre
    px = np.einsum("td,td->t", d, ux)
    py = np.einsum("td,td->t", d, uy)
    qx = np.abs(px) - half_l
    qy = np.abs(py) - half_w
    outside = np.hypot(np.maximum(qx, 0), np.maximum(qy, 0))
    inside = np.minimum(np.maximum(qx, qy), 0)
    return outside + inside - np.asarray(radius, dtype=float)


def tow_polygons(data, dims):
    """{vessel: (T, 4, 2) hull rectangles} from columns `<vessel>.x/.y/.psi` of `data`."""
    return {
        v: rectangle(data[f"{v}.x"], data[f"{v}.y"], data[f"{v}.psi"], dims[v]["length"], dims[v]["width"], dims[v]["centre"])
        for v in VESSELS
    }


def obstacle_slots(data):
    """Slot numbers k present in `data` as `obstacle[k].kind` columns."""
    k = 1
    slots = []
    while f"obstacle[{k}].kind" in data:
        slots.append(k)
        k += 1
    return slots


def hull_overlaps(data, dims):
    """Every overlap of a tow hull with a static hazard, a target ship or another tow hull.

    Returns a list of (pair name, first overlapping row, number of rows, deepest penetration in
    m); empty when nothing overlaps. `data` maps column names to arrays (the closed-loop CSV).
    Rows whose bounding circles are apart are cleared first; the exact tests run on the rest."""
    hulls = tow_polygons(data, dims)
    centres = {v: hulls[v].mean(axis=1) for v in VESSELS}
    radii = {v: math.hypot(dims[v]["length"], dims[v]["width"]) / 2 for v in VESSELS}
    found = []

    def near(v, centre, radius):
        return np.linalg.norm(centres[v] - centre, axis=-1) <= radii[v] + radius + 1e-9

    def polygon_pair(name, rows, p, q):
        if rows.size == 0:
            return
        hit = polygons_overlap(p, q)
        if hit.any():
            depth = penetration_depth(p[hit], q[hit])
            found.append((name, int(rows[hit][0]), int(hit.sum()), float(depth.max())))

    for a, b in (("ship", "tug1"), ("ship", "tug2"), ("tug1", "tug2")):
        rows = np.flatnonzero(near(a, centres[b], radii[b]))
        polygon_pair(f"{a}-{b}", rows, hulls[a][rows], hulls[b][rows])
    for k in obstacle_slots(data):
        kind = np.asarray(data[f"obstacle[{k}].kind"])
        ox, oy = np.asarray(data[f"obstacle[{k}].x"], dtype=float), np.asarray(data[f"obstacle[{k}].y"], dtype=float)
        length, width = np.asarray(data[f"obstacle[{k}].length"], dtype=float), np.asarray(data[f"obstacle[{k}].width"], dtype=float)
        centre = np.stack([ox, oy], axis=-1)
        for v in VESSELS:
            static = np.flatnonzero((kind == 1) & near(v, centre, length / 2))
            if static.size:
                gap = rectangle_circle_gap(hulls[v][static], ox[static], oy[static], length[static] / 2)
                hit = gap < 0
                if hit.any():
                    found.append((f"{v}-obstacle[{k}] (static)", int(static[hit][0]), int(hit.sum()), float(-gap[hit].min())))
            bound = np.maximum(length, width) / 2 / math.cos(math.pi / ELLIPSE_SEGMENTS)
            rows = np.flatnonzero((kind == 2) & near(v, centre, bound))
            if rows.size:
                poly = ellipse(ox[rows], oy[rows], np.asarray(data[f"obstacle[{k}].psi"], dtype=float)[rows], length[rows], width[rows])
                polygon_pair(f"{v}-obstacle[{k}] (target ship)", rows, hulls[v][rows], poly)
    return found


def wrap_angle(a):
    """Wrap to (-pi, pi]."""
    a = np.asarray(a, dtype=float)
    w = np.mod(a + math.pi, 2 * math.pi) - math.pi
    return np.where(w == -math.pi, math.pi, w)


def scenario_path_for_plant(scenario_arg, plant_resources=None):
    """The scenario file the plant loads: the given path, else the FMU's bundled paper.toml,
    else the repository's scenarios/paper.toml."""
    if scenario_arg:
        return pathlib.Path(scenario_arg)
    if plant_resources is not None and (pathlib.Path(plant_resources) / "paper.toml").is_file():
        return pathlib.Path(plant_resources) / "paper.toml"
    return pathlib.Path(__file__).resolve().parents[1] / "scenarios" / "paper.toml"
