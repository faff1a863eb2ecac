"""The optimal control problem of the paper, built symbolically with CasADi.

Robot: unicycle with state x = [px, py, theta, v] and control u = [a, omega]. The functions below
are what the C runtime evaluates at every SQP iteration; each is named after what it computes and
takes the runtime parameters (weights, q, d_th, kappa, distances) as inputs so that users can tune
without regenerating. Sizes (N, N_h) and the interval length dt are fixed at generation.

Cost conventions: ||r||^2_W = r' diag(W) r (no factor 1/2), exactly as in the paper. The QP takes
1/2 z' H z + g' z, so the Hessians returned here are the second derivatives of the cost (2 diag(W)
for the least-squares terms) and the runtime uses them as they are.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from .spec import Spec

NX = 4
NU = 2
NPOS = 2  # the distance rows and the collision cost touch only the position [px, py]

# Distances are smoothed as sqrt(dx^2 + dy^2 + eps^2): differentiable at 0 with a zero gradient
# there, and off by eps^2 / (2 d) <= 1e-6 m at d >= 0.5 m.
DIST_EPS = 1e-3


@dataclass(frozen=True)
class Port:
    """One input or output of a model function: its name and its dense shape (rows, cols)."""

    name: str
    rows: int
    cols: int = 1

    @property
    def size(self) -> int:
        return self.rows * self.cols


@dataclass(frozen=True)
class ModelFunction:
    """A CasADi function together with the description the templates and bindings need."""

    name: str  # without the spec's prefix, e.g. "dynamics"
    doc: str
    function: ca.Function
    inputs: tuple[Port, ...]
    outputs: tuple[Port, ...]


def smooth_distance(p: ca.SX, c: ca.SX) -> ca.SX:
    """Euclidean distance between the points p and c, smoothed at 0 (see DIST_EPS)."""
    return ca.sqrt(ca.sumsqr(p - c) + DIST_EPS**2)


def collision_potential(d: ca.SX, q: ca.SX, d_th: ca.SX, kappa: ca.SX) -> ca.SX:
    """The paper's f(d): linear below d_th, logistic above; C^2 and convex for d >= 0.

    The logistic branch is written with e = exp(-kappa (max(d, d_th) - d_th)) in (0, 1], so it never
    overflows, whatever kappa and d (CasADi evaluates both branches of if_else).
    """
    linear = -(kappa * q / 4.0) * d + (q / 2.0 + kappa * q * d_th / 4.0)
    e = ca.exp(-kappa * (ca.fmax(d, d_th) - d_th))
    logistic = q * e / (1.0 + e)
    return ca.if_else(d <= d_th, linear, logistic)


def reciprocal(x: ca.SX) -> ca.SX:
    """1 / x for x > 0, kept as one factor: CasADi rewrites a * (1 / x) into a / x at every use, so
    an expression that multiplies by a reciprocal k times would divide k times. The no-op fabs is an
    operation CasADi does not see through (and C compiles it to a bit mask; fmax would be a libm call)."""
    return ca.fabs(1.0 / x)


def collision_potential_derivatives(
    d: ca.SX, q: ca.SX, d_th: ca.SX, kappa: ca.SX
) -> tuple[ca.SX, ca.SX, ca.SX]:
    """f(d), f'(d) and f''(d) of collision_potential, differentiated by hand.

    With e as there and s = 1 / (1 + e), the logistic branch is f = q e s, f' = -kappa q e s^2 and
    f'' = kappa^2 q e (1 - e) s^3: one division where CasADi's derivatives of q e / (1 + e) take
    seven. Both branches meet at d_th with f' = -kappa q / 4 and f'' = 0 (tests compare all three
    with finite differences and with the paper's formulas).
    """
    # the excess over d_th as a select, not fmax: in C99 CasADi's fmax is a libm call
    e = ca.exp(-kappa * ca.if_else(d > d_th, d - d_th, 0.0))
    s = reciprocal(1.0 + e)
    below = d <= d_th
    f = ca.if_else(below, -(kappa * q / 4.0) * d + (q / 2.0 + kappa * q * d_th / 4.0), q * e * s)
    df = ca.if_else(below, -(kappa * q / 4.0), -kappa * q * e * s * s)
    d2f = ca.if_else(below, 0.0, kappa * kappa * q * e * (1.0 - e) * s * s * s)
    return f, df, d2f


def unicycle_ode(x: ca.SX, u: ca.SX) -> ca.SX:
    return ca.vertcat(x[3] * ca.cos(x[2]), x[3] * ca.sin(x[2]), u[1], u[0])


def rk4_step(x: ca.SX, u: ca.SX, dt: float, steps: int) -> ca.SX:
    h = dt / steps
    for _ in range(steps):
        k1 = unicycle_ode(x, u)
        k2 = unicycle_ode(x + h / 2 * k1, u)
        k3 = unicycle_ode(x + h / 2 * k2, u)
        k4 = unicycle_ode(x + h * k3, u)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x


class OcpModel:
    """The model functions of one spec. Symbolic expressions are built once, in the constructor."""

    def __init__(self, spec: Spec) -> None:
        self.spec = spec
        x = ca.SX.sym("x", NX)
        u = ca.SX.sym("u", NU)
        g = ca.SX.sym("g", NX)
        p = ca.SX.sym("p", NPOS)
        c = ca.SX.sym("c", NPOS)
        w_goal = ca.SX.sym("w_goal", NX)
        w_control = ca.SX.sym("w_control", NU)
        w_terminal = ca.SX.sym("w_goal_terminal", NX)
        q = ca.SX.sym("q")
        d_th = ca.SX.sym("d_th")
        kappa = ca.SX.sym("kappa")
        d_min = ca.SX.sym("d_min")

        functions = []

        # Discrete dynamics and their Jacobians.
        x_next = rk4_step(x, u, spec.dt, spec.integrator.steps)
        functions.append(
            self._make(
                "dynamics",
                f"x_next = RK4 ({spec.integrator.steps} step(s)) of the unicycle over dt = {spec.dt:g} s, "
                "and its Jacobians A = d x_next / d x, B = d x_next / d u",
                [("x", x), ("u", u)],
                [("x_next", x_next), ("A", ca.jacobian(x_next, x)), ("B", ca.jacobian(x_next, u))],
            )
        )

        # Curvature of the dynamics weighted by their multipliers: the part of the Lagrangian's
        # Hessian that Gauss-Newton leaves out (the full-SQP mode uses it, convexified per stage).
        pi = ca.SX.sym("pi", NX)
        z = ca.vertcat(x, u)
        hess_dyn = ca.hessian(ca.dot(pi, x_next), z)[0]
        functions.append(
            self._make(
                "dynamics_hessian",
                "Hessian of pi' x_next(x, u) with respect to (x, u), in blocks xx, ux, uu",
                [("x", x), ("u", u), ("pi", pi)],
                [("hess_xx", hess_dyn[:NX, :NX]), ("hess_ux", hess_dyn[NX:, :NX]), ("hess_uu", hess_dyn[NX:, NX:])],
            )
        )

        # Least-squares goal and control terms: exact (constant, PSD) Hessians.
        r_goal = x - g
        l_stage = ca.dot(w_goal * r_goal, r_goal) + ca.dot(w_control * u, u)
        functions.append(
            self._make(
                "cost_stage",
                "stage goal + control cost ||x - g||^2_Wg + ||u||^2_Wu, its gradient and Hessian",
                [("x", x), ("u", u), ("g", g), ("w_goal", w_goal), ("w_control", w_control)],
                [
                    ("l", l_stage),
                    ("grad_x", ca.gradient(l_stage, x)),
                    ("grad_u", ca.gradient(l_stage, u)),
                    ("hess_x", ca.hessian(l_stage, x)[0]),
                    ("hess_u", ca.hessian(l_stage, u)[0]),
                ],
            )
        )
        l_terminal = ca.dot(w_terminal * r_goal, r_goal)
        functions.append(
            self._make(
                "cost_terminal",
                "terminal goal cost ||x_N - g||^2_WgN, its gradient and Hessian",
                [("x", x), ("g", g), ("w_goal_terminal", w_terminal)],
                [
                    ("l", l_terminal),
                    ("grad_x", ca.gradient(l_terminal, x)),
                    ("hess_x", ca.hessian(l_terminal, x)[0]),
                ],
            )
        )

        # Collision cost of one human: convex-over-nonlinear f(d(p, h)). The generalised
        # Gauss-Newton Hessian f''(d) grad d grad d' is PSD because f'' >= 0; the gradient is exact.
        # It is evaluated for every human at every node of every step, so the derivatives are
        # written out: grad d = (p - h) / d and hess d = (I - grad d grad d') / d share one
        # reciprocal, and f', f'' one more (collision_potential_derivatives).
        d_sym = ca.SX.sym("d")
        f_of_d, df, d2f = collision_potential_derivatives(d_sym, q, d_th, kappa)
        potential = ca.Function("f", [d_sym, q, d_th, kappa], [f_of_d, df, d2f])
        dist = smooth_distance(p, c)
        inv_dist = reciprocal(dist)
        grad_d = (p - c) * inv_dist
        f_val, f_d, f_dd = collision_potential_derivatives(dist, q, d_th, kappa)
        hess_d = (ca.SX.eye(NPOS) - grad_d @ grad_d.T) * inv_dist
        hess_gn = f_dd * (grad_d @ grad_d.T)
        collision_in = [("p", p), ("h", c), ("q", q), ("d_th", d_th), ("kappa", kappa)]
        collision_gn_out = [("f", f_val), ("grad_p", f_d * grad_d), ("hess_gn_p", hess_gn)]
        functions.append(
            self._make(
                "cost_collision",
                "collision cost f(d(p, h)) of one human at predicted position h, its exact gradient, "
                "its Gauss-Newton Hessian f''(d) grad d grad d' and its exact Hessian",
                collision_in,
                [*collision_gn_out, ("hess_p", hess_gn + f_d * hess_d)],
            )
        )
        # The same without the exact Hessian, for the Gauss-Newton steps (every RTI step, for every
        # human at every node): CasADi evaluates every output, and the exact Hessian's terms were a
        # seventh of the preparation (docs/benchmarks.md).
        functions.append(
            self._make(
                "cost_collision_gn",
                "collision cost f(d(p, h)) of one human at predicted position h, its exact gradient and "
                "its Gauss-Newton Hessian f''(d) grad d grad d' (cost_collision without the exact Hessian)",
                collision_in,
                collision_gn_out,
            )
        )

        # Distance rows: d(p, c) - d_min >= 0 for a human's current position (d_h) and the
        # closest obstacle (d_s).
        functions.append(
            self._make(
                "distance_constraint",
                "distance row d(p, c) - d_min (>= 0 when satisfied), its Jacobian and Hessian w.r.t. p",
                [("p", p), ("c", c), ("d_min", d_min)],
                [("g", dist - d_min), ("jac_p", grad_d.T), ("hess_p", hess_d)],
            )
        )

        self.functions: tuple[ModelFunction, ...] = tuple(functions)
        self.potential = potential  # f, f', f'' of a scalar distance, for tests and plots

    def __getitem__(self, name: str) -> ModelFunction:
        for mf in self.functions:
            if mf.name == name:
                return mf
        raise KeyError(f"no model function {name!r}; have {[mf.name for mf in self.functions]}")

    @staticmethod
    def _make(
        name: str, doc: str, inputs: list[tuple[str, ca.SX]], outputs: list[tuple[str, ca.SX]]
    ) -> ModelFunction:
        # Dense outputs: the C runtime reads fixed column-major blocks, never CasADi sparsity.
        fn = ca.Function(
            name,
            [e for _, e in inputs],
            [ca.densify(e) for _, e in outputs],
            [n for n, _ in inputs],
            [n for n, _ in outputs],
        )
        return ModelFunction(
            name=name,
            doc=doc,
            function=fn,
            inputs=tuple(Port(n, e.size1(), e.size2()) for n, e in inputs),
            outputs=tuple(Port(n, e.size1(), e.size2()) for n, e in outputs),
        )
