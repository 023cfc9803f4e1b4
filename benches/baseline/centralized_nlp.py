"""The centralized MPC's problem (towing_mpc::Centralized, Du, Negenborn, Reppa 2022,
eq. (12), as docs/controller-design.md "Centralized MPC (12)" builds it) as a CasADi NLP
for IPOPT, from the `problem` section that
crates/towing-control/examples/record_centralized.rs writes.

The same problem, term by term (the Rust source each line follows in brackets):

- models: the ship of eq. (15) and the tugs of eq. (16) in Fossen's form with the
  hull's M, M^-1 and damping (towing_model::kinetics, `nu_dot_expanded`), the towline
  loads along the planned towing angles (towing_mpc::lines, towline::line_loads), zero-
  order hold over T_s = 1 s integrated by RK4 in `substeps` equal steps (rk4.rs,
  params.rs); the tugs pulled with tension F_ih along the bearing psi_S(h) + alpha_ih,
  psi_S(h) the ship's predicted heading at the start of sample h (centralized.rs
  `Problem::pulls`, tug.rs `TowlinePull::from_plan`); tug headings unwrapped next to the
  ship's (centralized.rs `Start::of`);
- the ship's stage terms (ship_mpc.rs `ship_stage_terms`): w_S1 |eta - eta_d|^2 (heading
  wrapped), w_S2 |nu|^2, w_F F^2 (and w_alpha alpha^2), the one-sided heading floor
  w_P min(0, psi - psi_floor)^2, the terminal term w |e_H + tau eta_dot_H|^2, and the
  motion limits (costs.rs `MotionLimits`: drift, sternway and speed rows, each a gap with
  the exact penalty W max(0, b - g(x)) like the clearance rows);
- the tugs' terms (centralized.rs `Problem::accumulate`): w_i1 |g_i - f_i|^2 with f_i the
  formation pose (formation.rs, towline::formation_pose), w_i2 |nu_i|^2, and the thrust
  rate term w_dtau sum |tau_h - tau_h-1|^2 (centralized.rs `thrust_rate_terms`);
- every vessel's obstacle terms (scp.rs `obstacle_terms`): w_3 phi(d) with phi the
  distance cost made honest (obstacle.rs `DistanceCost::eval`) and d the circle or focal
  ellipse distance of the obstacle moved on by its drift (obstacle.rs
  `Obstacle::distance`, `Obstacle::after`), and the clearance penalty W max(0, d_min - d)
  (scp.rs `ClearanceParams::penalty_at`);
- the configuration restriction g_i = f_i as the exact L1 penalty W_c sum |g_i - f_i|.

Decision variables: the 30 inputs (per sample h: F1, F2, alpha1, alpha2, X1, Y1, N1, X2,
Y2, N2, index 10 h + k as in centralized.rs), one slack t >= |g_i - f_i| per consensus
component (two rows, t - r >= 0 and t + r >= 0) and one slack s >= max(0, d_min - d) per
vessel, sample and obstacle (one row, s + d - d_min >= 0): the exact penalties become
smooth (the standard reformulation, Nocedal and Wright 2006, section 17.2). Bounds: the
ship's box (eq. (17)-(18)), the first sample's rate bounds from the previous command
(clamped into the box first, ship_mpc.rs `ShipMpcParams::project`), as variable bounds;
the rate bounds between samples (eq. (20)-(21)) as 16 linear rows; the tugs' thrust box
(eq. (19)). The slacks have no upper bound (the Rust QP caps its linearised slacks at
10 m and 10 rad, which no recorded sample comes near): this is min merit(u) over the
bounds, the merit `Centralized::evaluate` computes.

`merit_function` gives the merit itself (exact |.| and max(0, .) instead of slacks) for
the cross-check against Rust's `Centralized::evaluate` on the same plans.
"""

from __future__ import annotations

import math

import casadi as ca

PER_STEP = 10  # inputs per sample: 4 ship, 3 + 3 tugs
TAU = 2.0 * math.pi


# ---- numbers (parameters, warm starts): the Rust arithmetic in Python floats ----------------


def angle_difference_float(a: float, b: float) -> float:
    """scp.rs `angle_difference`: a - b wrapped to (-pi, pi] via f64::rem_euclid."""
    d = math.fmod(a - b, TAU)
    if d < 0.0:
        d += TAU
    return d - TAU if d > math.pi else d


def obstacle_parameters(o: dict, cost_on: bool) -> list[float]:
    """[cx, cy, a, focal, cos, sin, drift_x, drift_y, cost_on] of a recorded obstacle; a circle
    is the focal form with a = radius and focal distance 0, which gives exactly |p - c| - R;
    cost_on is 0 for an obstacle the sample leaves out of the distance cost (costs.rs
    `obstacle_terms`, `distance_cost_off`)."""
    flag = 1.0 if cost_on else 0.0
    if o["kind"] == "circle":
        r = o["radius"]
        return [o["centre"][0], o["centre"][1], r, 0.0, 1.0, 0.0, 0.0, 0.0, flag]
    a, b, th = o["semi_major"], o["semi_minor"], o["orientation"]
    f = math.sqrt(max(a * a - b * b, 0.0))
    return [o["centre"][0], o["centre"][1], a, f, math.cos(th), math.sin(th), o["drift"][0], o["drift"][1],
            flag]


OBSTACLE_PARAMS = 9


def parameters(sample: dict) -> list[float]:
    """The NLP's parameter vector of a recorded sample: ship state (6), tug states with
    headings unwrapped next to the ship's (12), previous tug thrusts (6), reference (9),
    heading floor and whether it is on (2), obstacles (9 each)."""
    ship = list(sample["ship"])
    p = list(ship)
    for tug in sample["tugs"]:
        t = list(tug)
        t[2] = ship[2] + angle_difference_float(t[2], ship[2])
        p += t
    for tau in sample["previous"]["tugs"]:
        p += list(tau)
    for ref in sample["reference"]:
        p += list(ref)
    floor = sample["heading_floor"]
    p += [0.0, 0.0] if floor is None else [floor, 1.0]
    off = sample.get("distance_cost_off", 0)
    for j, o in enumerate(sample["obstacles"]):
        p += obstacle_parameters(o, (off >> j) & 1 == 0)
    return p


# ---- the model ------------------------------------------------------------------------------


def angle_difference(a, b):
    """angle_difference on CasADi expressions (floor: derivative 0 away from the jumps)."""
    x = a - b
    m = x - TAU * ca.floor(x / TAU)
    return ca.if_else(m > math.pi, m - TAU, m)


def nu_dot(hull: dict, nu, tau):
    """towing_model::kinetics `nu_dot_expanded` with the damping of Skjetne et al. (2004)."""
    M, Mi, d = hull["mass_matrix"], hull["mass_matrix_inv"], hull["damping"]
    u, v, r = nu
    au, av, ar = ca.fabs(u), ca.fabs(v), ca.fabs(r)
    d11 = -d["x_u"] - d["x_absu_u"] * au - d["x_uuu"] * u * u
    d22 = -d["y_v"] - d["y_absv_v"] * av - d["y_absr_v"] * ar
    d23 = -d["y_r"] - d["y_absv_r"] * av - d["y_absr_r"] * ar
    d32 = -d["n_v"] - d["n_absv_v"] * av - d["n_absr_v"] * ar
    d33 = -d["n_r"] - d["n_absv_r"] * av - d["n_absr_r"] * ar
    a = M[1][0] * u + M[1][1] * v + M[1][2] * r
    b = M[0][0] * u + M[0][1] * v + M[0][2] * r
    cnu = [-a * r, b * r, a * u - b * v]
    dnu = [d11 * u, d22 * v + d23 * r, d32 * v + d33 * r]
    rhs = [tau[k] - cnu[k] - dnu[k] for k in range(3)]
    return [Mi[k][0] * rhs[0] + Mi[k][1] * rhs[1] + Mi[k][2] * rhs[2] for k in range(3)]


def line_direction(line: int, bearing):
    """lines.rs `line_direction`: unit vector from the ship's towing point to the tug's."""
    c, s = ca.cos(bearing), ca.sin(bearing)
    return [-c, -s] if line == 0 else [c, s]


def rk4(f, x, n: int, h: float):
    """rk4.rs `integrate`: n classical RK4 steps of h."""
    x = list(x)
    for _ in range(n):
        k1 = f(x)
        k2 = f([x[i] + 0.5 * h * k1[i] for i in range(6)])
        k3 = f([x[i] + 0.5 * h * k2[i] for i in range(6)])
        k4 = f([x[i] + h * k3[i] for i in range(6)])
        x = [x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) for i in range(6)]
    return x


def kinematics(x, nud):
    c, s = ca.cos(x[2]), ca.sin(x[2])
    return [c * x[3] - s * x[4], s * x[3] + c * x[4], x[5], nud[0], nud[1], nud[2]]


def ship_step(problem: dict, x, u):
    """ship.rs `ShipModel::step`: the towline loads in the body frame held over the sample."""
    hull = problem["ship_hull"]
    points = [hull["stern_tow_point_x"], hull["bow_tow_point_x"]]
    tau = [0.0, 0.0, 0.0]
    for line in range(2):
        e = line_direction(line, u[2 + line])
        f = [u[line] * e[0], u[line] * e[1]]
        tau = [tau[0] + f[0], tau[1] + f[1], tau[2] + points[line] * f[1]]
    return rk4(lambda s: kinematics(s, nu_dot(hull, s[3:], tau)), x, problem["substeps"], problem["substep"])


def tug_step(problem: dict, line: int, x, thrust, tension, bearing):
    """tug.rs `TugModel::step`: the line's reaction -F e at the tug's towing point, turning
    in the tug's body frame as it yaws (world-fixed bearing)."""
    hull = problem["tug_hulls"][line]
    xt = hull["bow_tow_point_x"] if line == 0 else hull["stern_tow_point_x"]
    e = line_direction(line, bearing)
    f = [-tension * e[0], -tension * e[1]]

    def derivative(s):
        c, sn = ca.cos(s[2]), ca.sin(s[2])
        fx = c * f[0] + sn * f[1]
        fy = -sn * f[0] + c * f[1]
        forces = [thrust[0] + fx, thrust[1] + fy, thrust[2] + xt * fy]
        return kinematics(s, nu_dot(hull, s[3:], forces))

    return rk4(derivative, x, problem["substeps"], problem["substep"])


def formation_pose(problem: dict, line: int, eta, alpha):
    """formation.rs `FormationMap::tug_reference` (towline::formation_pose, heading unwrapped)."""
    ship, tug = problem["ship_hull"], problem["tug_hulls"][line]
    length = problem["towline_desired_length"][line]
    c, s = ca.cos(eta[2]), ca.sin(eta[2])
    heading = eta[2] + alpha
    ch, sh = ca.cos(heading), ca.sin(heading)
    if line == 0:
        xb, offset, side = ship["stern_tow_point_x"], length + tug["bow_tow_point_x"], -1.0
    else:
        xb, offset, side = ship["bow_tow_point_x"], length - tug["stern_tow_point_x"], 1.0
    p = [eta[0] + c * xb, eta[1] + s * xb]
    return [p[0] + side * offset * ch, p[1] + side * offset * sh, heading]


def phi(distance: dict, d):
    """obstacle.rs `DistanceCost::eval`: (d - d_safe)^-2 above d_safe + epsilon, its
    quadratic extension (value, slope, curvature matched) below."""
    ds, d0 = distance["d_safe"], distance["d_safe"] + distance["epsilon"]
    t0 = 1.0 / (d0 - ds)
    v0, s0, c0 = t0 * t0, -2.0 * t0 * t0 * t0, 6.0 * t0 ** 4
    t = 1.0 / (ca.fmax(d, d0) - ds)
    e = d - d0
    return ca.if_else(d >= d0, t * t, v0 + s0 * e + 0.5 * c0 * e * e)


def obstacle_distance(o, samples_ahead: int, pos):
    """obstacle.rs `Obstacle::after(samples).distance(pos)` on the focal form."""
    cx, cy = o[0] + samples_ahead * o[6], o[1] + samples_ahead * o[7]
    total = 0
    for sign in (1.0, -1.0):
        dx = pos[0] - cx - sign * o[3] * o[4]
        dy = pos[1] - cy - sign * o[3] * o[5]
        total = total + ca.sqrt(dx * dx + dy * dy)
    return 0.5 * total - o[2]


# ---- the cost -------------------------------------------------------------------------------


class Terms:
    """The pieces of the cost of one plan: the smooth part, the consensus residuals and the
    clearance gaps d_min - d with their penalties."""

    def __init__(self):
        self.smooth = 0
        self.consensus = []
        self.gaps = []  # (d_min - d, W)


def unpack(p, n_obs: int):
    """Named views of the parameter vector (`parameters`)."""
    at = 0

    def take(n):
        nonlocal at
        out = [p[at + k] for k in range(n)]
        at += n
        return out

    x_ship = take(6)
    x_tugs = [take(6), take(6)]
    previous_tugs = [take(3), take(3)]
    reference = [take(3) for _ in range(3)]
    floor, floor_on = take(2)
    obstacles = [take(OBSTACLE_PARAMS) for _ in range(n_obs)]
    return x_ship, x_tugs, previous_tugs, reference, (floor, floor_on), obstacles


def obstacle_terms(terms: Terms, params: dict, weight: float, obstacles, h: int, pos):
    """scp.rs `obstacle_terms` (every obstacle gets a clearance row: the controller selects
    at most `max_obstacles` of them)."""
    cl = params["clearance"]
    for o in obstacles:
        d = obstacle_distance(o, h + 1, pos)
        if weight > 0.0:
            terms.smooth = terms.smooth + o[8] * weight * phi(params["distance"], d)
        terms.gaps.append((cl["min_distance"] - d, cl["penalty"]))


def motion_terms(terms: Terms, sp: dict, x):
    """costs.rs `MotionLimits::terms`: the drift, sternway and speed rows as gaps b - g(x)."""
    m = sp["motion"]
    if m["penalty"] <= 0.0:
        return
    t = math.tan(m["max_drift"])
    for bound, g in [(-m["sway_allowance"], t * x[3] - x[4]), (-m["sway_allowance"], t * x[3] + x[4]),
                     (-m["max_sternway"], x[3]), (-m["max_speed"], -x[3])]:
        terms.gaps.append((bound - g, m["penalty"]))


def ship_stage(terms: Terms, sp: dict, x, ref, u, last: bool, floor):
    """ship_mpc.rs `ship_stage_terms`."""
    value, on = floor
    e = angle_difference(x[2], value)
    terms.smooth = terms.smooth + on * sp["weight_port_turn"] * ca.fmin(e, 0.0) ** 2
    err = [x[0] - ref[0], x[1] - ref[1], angle_difference(x[2], ref[2])]
    for c in range(3):
        terms.smooth = (terms.smooth + sp["pose_weights"][c] * err[c] ** 2
                        + sp["velocity_weights"][c] * x[3 + c] ** 2)
    for k, w in enumerate([sp["weight_tension"]] * 2 + [sp["weight_towing_angle"]] * 2):
        if w > 0.0:
            terms.smooth = terms.smooth + w * u[k] ** 2
    if last and sp["terminal"] is not None:
        tw, th = sp["terminal"]["weight"], sp["terminal"]["horizon"]
        c, s = ca.cos(x[2]), ca.sin(x[2])
        xdot = [c * x[3] - s * x[4], s * x[3] + c * x[4], x[5]]
        for k in range(3):
            terms.smooth = terms.smooth + tw * (err[k] + th * xdot[k]) ** 2


def cost_terms(problem: dict, u, p, n_obs: int) -> Terms:
    """The cost of the plan `u` (30 inputs) for the parameters `p`: centralized.rs
    `Problem::rollout` then `Problem::accumulate`."""
    H = problem["horizon"]
    sp, tp, cp = problem["ship"], problem["tug"], problem["centralized"]
    x_ship, x_tugs, prev_tugs, reference, floor, obstacles = unpack(p, n_obs)
    ship_u = [[u[PER_STEP * h + k] for k in range(4)] for h in range(H)]
    tug_u = [[[u[PER_STEP * h + 4 + 3 * i + c] for c in range(3)] for h in range(H)] for i in range(2)]
    ship_x, x = [], x_ship
    for h in range(H):
        x = ship_step(problem, x, ship_u[h])
        ship_x.append(x)
    tug_x = []
    for i in range(2):
        states, x = [], x_tugs[i]
        for h in range(H):
            psi = x_ship[2] if h == 0 else ship_x[h - 1][2]
            x = tug_step(problem, i, x, tug_u[i][h], ship_u[h][i], psi + ship_u[h][2 + i])
            states.append(x)
        tug_x.append(states)
    terms = Terms()
    for h in range(H):
        x = ship_x[h]
        ship_stage(terms, sp, x, reference[h], ship_u[h], h + 1 == H, floor)
        motion_terms(terms, sp, x)
        obstacle_terms(terms, sp, sp["weight_distance"], obstacles, h, x[:2])
        for i in range(2):
            g = tug_x[i][h]
            f = formation_pose(problem, i, x[:3], ship_u[h][2 + i])
            res = [g[0] - f[0], g[1] - f[1], angle_difference(g[2], f[2])]
            for c in range(3):
                terms.consensus.append(res[c])
                terms.smooth = (terms.smooth + tp["pose_weights"][c] * res[c] ** 2
                                + tp["velocity_weights"][c] * g[3 + c] ** 2)
            if h == 0:
                for k in range(H):
                    before = prev_tugs[i] if k == 0 else tug_u[i][k - 1]
                    for c in range(3):
                        w = cp["thrust_rate_weights"][c]
                        terms.smooth = terms.smooth + w * (tug_u[i][k][c] - before[c]) ** 2
            obstacle_terms(terms, tp, tp["weight_distance"], obstacles, h, g[:2])
    return terms


def n_params(n_obs: int) -> int:
    return 6 + 12 + 6 + 9 + 2 + OBSTACLE_PARAMS * n_obs


def merit_function(problem: dict, n_obs: int) -> ca.Function:
    """merit(u, p) = smooth + W_c sum |r| + sum W max(0, d_min - d), and the L1 norm of the
    consensus residuals: the value `Centralized::evaluate` computes (its `total()` plus
    `W_c consensus_l1`)."""
    u = ca.SX.sym("u", PER_STEP * problem["horizon"])
    p = ca.SX.sym("p", n_params(n_obs))
    t = cost_terms(problem, u, p, n_obs)
    l1 = sum(ca.fabs(r) for r in t.consensus)
    penalty = sum(w * ca.fmax(g, 0.0) for g, w in t.gaps) if t.gaps else 0
    merit = t.smooth + problem["centralized"]["consensus_penalty"] * l1 + penalty
    return ca.Function("merit", [u, p], [merit, l1], ["u", "p"], ["merit", "consensus_l1"])


class Nlp:
    """The NLP for `n_obs` obstacles, built once (module docs): variables
    [u (30), t (consensus), s (clearance)], constraints [rate rows, consensus rows,
    clearance rows]."""

    def __init__(self, problem: dict, n_obs: int, ipopt_options: dict):
        H = problem["horizon"]
        self.problem, self.n_obs, self.n_u = problem, n_obs, PER_STEP * H
        u = ca.SX.sym("u", self.n_u)
        p = ca.SX.sym("p", n_params(n_obs))
        terms = cost_terms(problem, u, p, n_obs)
        self.n_cons, self.n_gaps = len(terms.consensus), len(terms.gaps)
        t = ca.SX.sym("t", self.n_cons)
        s = ca.SX.sym("s", self.n_gaps)
        w_c = problem["centralized"]["consensus_penalty"]
        objective = terms.smooth + w_c * ca.sum1(t)
        for k, (_, w) in enumerate(terms.gaps):
            objective = objective + w * s[k]
        rows = []
        for h in range(1, H):
            rows += [u[PER_STEP * h + k] - u[PER_STEP * (h - 1) + k] for k in range(4)]
        self.n_rate = len(rows)
        for m, r in enumerate(terms.consensus):
            rows += [t[m] - r, t[m] + r]
        for k, (gap, _) in enumerate(terms.gaps):
            rows.append(s[k] - gap)
        self.n_x = self.n_u + self.n_cons + self.n_gaps
        nlp = {"x": ca.vertcat(u, t, s), "p": p, "f": objective, "g": ca.vertcat(*rows)}
        self.solver = ca.nlpsol("ipopt_centralized", "ipopt", nlp, {"expand": True, "ipopt": ipopt_options,
                                                                       "print_time": False})
        self.aux = ca.Function("aux", [u, p], [ca.vertcat(*terms.consensus),
                                               ca.vertcat(*[g for g, _ in terms.gaps]) if terms.gaps
                                               else ca.DM.zeros(0, 1)])
        rate = [problem["ship"]["tension_rate"]] * 2 + [problem["ship"]["angle_rate"]] * 2
        inf = ca.inf
        self.lbg = [-rate[k] for _ in range(1, H) for k in range(4)] + [0.0] * (2 * self.n_cons + self.n_gaps)
        self.ubg = [rate[k] for _ in range(1, H) for k in range(4)] + [inf] * (2 * self.n_cons + self.n_gaps)

    def bounds(self, previous_ship: list[float]) -> tuple[list[float], list[float]]:
        """Variable bounds: the ship's box with the first sample's rate bounds from the
        previous command clamped into the box (ship_mpc.rs `project`), the tugs' box, the
        slacks >= 0."""
        sp, H = self.problem["ship"], self.problem["horizon"]
        box = [(sp["min_tension"], sp["max_tension"], sp["tension_rate"])] * 2 + \
              [(-sp["max_angle"], sp["max_angle"], sp["angle_rate"])] * 2
        lim = self.problem["tug"]["thrust_limit"]
        lbx, ubx = [], []
        for h in range(H):
            for k, (lo, hi, rate) in enumerate(box):
                if h == 0:
                    prev = min(max(previous_ship[k], lo), hi)
                    lbx.append(max(lo, prev - rate))
                    ubx.append(min(hi, prev + rate))
                else:
                    lbx.append(lo)
                    ubx.append(hi)
            for _ in range(2):
                lbx += [-lim[0], -lim[1], -lim[2]]
                ubx += list(lim)
        n_slack = self.n_cons + self.n_gaps
        return lbx + [0.0] * n_slack, ubx + [ca.inf] * n_slack

    def initial_slacks(self, u0: list[float], p: list[float]) -> list[float]:
        """Slacks that make the initial plan feasible: |r| and max(0, d_min - d)."""
        r, gaps = self.aux(u0, p)
        return [abs(float(v)) for v in ca.vertsplit(r)] + [max(float(v), 0.0) for v in ca.vertsplit(gaps)]


def plan_vector(plan: dict) -> list[float]:
    """The 30 inputs of a plan {"ship": [[4] x H], "tugs": [[[3] x H] x 2]} (index 10 h + k)."""
    u = []
    for h in range(len(plan["ship"])):
        u += list(plan["ship"][h]) + list(plan["tugs"][0][h]) + list(plan["tugs"][1][h])
    return u


def plan_dict(u, horizon: int) -> dict:
    """The inverse of `plan_vector`."""
    u = [float(v) for v in u]
    return {
        "ship": [u[PER_STEP * h:PER_STEP * h + 4] for h in range(horizon)],
        "tugs": [[u[PER_STEP * h + 4 + 3 * i:PER_STEP * h + 7 + 3 * i] for h in range(horizon)] for i in range(2)],
    }


def shifted(u: list[float], horizon: int) -> list[float]:
    """The warm start: the plan one sample ahead, the last sample repeated (centralized.rs
    `Centralized::shift`)."""
    out = []
    for h in range(horizon):
        k = min(h + 1, horizon - 1)
        out += list(u[PER_STEP * k:PER_STEP * (k + 1)])
    return out


def cold_start(sample: dict, horizon: int) -> list[float]:
    """The cold start: the previous command repeated (centralized.rs `solve_sample`)."""
    prev = sample["previous"]
    return (list(prev["ship"]) + list(prev["tugs"][0]) + list(prev["tugs"][1])) * horizon
