"""Independent models of six MultiBody.Examples.Elementary examples (issue 25).

    python benchmarks/msl_multibody_truth.py --refs REFS [EXAMPLE...]

Each example is written here again from its physics, not from MSL's equations (no
springc): RollingWheel (Newton-Euler with the contact force eliminated, no slip),
DoublePendulumInitTip (Lagrange's equations of two BodyBox links and the damper),
ForceAndTorque (Lagrange's equations of the cylinder on two revolute joints),
PointGravity and PointGravityWithPointMasses (point masses, mu = 1, the spring c = 10)
and PointGravityWithPointMasses2 (a rigid body of six unit point masses, mu = 5). Each
runs with scipy's DOP853 and Radau at rtol 1e-12, prints how far the two differ, the
drift of the model's invariant (energy; with the damper, energy plus the dissipated
work), the reference's own drift of the same invariant computed from its signals, and
the worst ``|a - b| / max(1, |b|)`` against the reference (the benchmark's measure),
then saves the DOP853 solution on the reference's grid as ``/tmp/truth-EXAMPLE.npy``
(time, then the state in the order of the model below) for a comparison with springc.
Gravity is MSL's ``g_n = 9.80665`` (World's default; 9.81 makes RollingWheel's energy
wander by 1e-3 in every run). RollingWheel takes about 2.5 min of CPU per method.
"""
from __future__ import annotations

import argparse
import csv
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

G_N = 9.80665
E1, E2, E3 = np.eye(3)
PACKAGE = "Modelica/Mechanics/MultiBody/Examples/Elementary"


def reference(refs: Path, name: str) -> tuple[np.ndarray, Callable[[str], np.ndarray]]:
    with open(refs / PACKAGE / name / f"{name}.csv") as stream:
        rows = list(csv.reader(stream))
    header, values = rows[0], np.array([[float(v) for v in r] for r in rows[1:]])
    return values[:, 0], lambda signal: values[:, header.index(signal)]


def solve(rhs: Callable, s0: np.ndarray, stop: float, grid: np.ndarray) -> np.ndarray:
    """DOP853 and Radau at rtol 1e-12; prints their difference, returns DOP853's."""
    out = [solve_ivp(rhs, (0.0, stop), s0, method=m, rtol=1e-12, atol=1e-14,
                     dense_output=True).sol(grid) for m in ("DOP853", "Radau")]
    print(f"  DOP853 vs Radau (rtol 1e-12): max |difference| {np.abs(out[0] - out[1]).max():.2e}")
    return out[0]


def report(name: str, grid: np.ndarray, energy: np.ndarray, ref_energy: np.ndarray,
           ours: dict[str, np.ndarray], col: Callable[[str], np.ndarray]) -> None:
    print(f"  invariant drift: independent {np.abs(energy - energy[0]).max():.2e}, "
          f"reference {np.abs(ref_energy - ref_energy[0]).max():.2e} "
          f"(reference at the end {ref_energy[-1] - ref_energy[0]:+.2e})")
    worst, where = 0.0, ""
    for signal, value in ours.items():
        theirs = col(signal)
        error = np.abs(value - theirs) / np.maximum(1.0, np.abs(theirs))
        if error.max() > worst:
            worst, where = float(error.max()), f"{signal} at t = {grid[error.argmax()]:.4f}"
    print(f"  independent vs reference: worst {worst:.3e} ({where})")


def rot(axis: int, angle: np.ndarray) -> np.ndarray:
    """Frames.TransformationMatrices.axisRotation (world to frame), complex-safe."""
    c, s = np.cos(angle), np.sin(angle)
    if axis == 1:
        return np.array([[1, 0, 0], [0, c, s], [0, -s, c]])
    if axis == 2:
        return np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])
    return np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])


def skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


WHEEL_RADIUS, WHEEL_MASS, WHEEL_INERTIA = 0.3, 2.0, np.diag([0.12, 0.06, 0.12])


def wheel_t(a: np.ndarray) -> np.ndarray:
    """World to wheel frame for Joints.RollingWheel's angles (sequence {3, 2, 1})."""
    return rot(1, a[2]) @ rot(2, a[1]) @ rot(3, a[0])


def wheel_jac(a: np.ndarray) -> np.ndarray:
    """w_a = wheel_jac(angles) @ der_angles (Frames.axesRotations)."""
    return np.column_stack([rot(1, a[2]) @ rot(2, a[1]) @ E3, rot(1, a[2]) @ E2, E1])


def wheel_delta(a: np.ndarray) -> np.ndarray:
    """From the wheel centre to the contact point on the plane z = 0, world frame."""
    axis = wheel_t(a).T @ E2
    aux = np.cross(E3, axis)
    return WHEEL_RADIUS * np.cross(aux / np.sqrt(aux @ aux), axis)


def wheel_vel(a: np.ndarray) -> np.ndarray:
    """v_0 = wheel_vel(angles) @ der_angles: the contact point does not move."""
    return skew(wheel_delta(a)) @ wheel_t(a).T @ wheel_jac(a)


def wheel_rhs(_t: float, s: np.ndarray) -> np.ndarray:
    """State angles, der_angles, x, y: Newton-Euler with the contact force eliminated."""
    a, d = s[:3], s[3:6]
    jdot = np.imag(wheel_jac(a + 1e-20j * d) @ d) / 1e-20  # complex-step d/dt
    vdot = np.imag(wheel_vel(a + 1e-20j * d) @ d) / 1e-20
    arm = WHEEL_MASS * wheel_t(a) @ skew(wheel_delta(a))
    w, inertia = wheel_jac(a) @ d, WHEEL_INERTIA
    dd = np.linalg.solve(inertia @ wheel_jac(a) - arm @ wheel_vel(a),
                         arm @ (vdot + G_N * E3) - inertia @ jdot - np.cross(w, inertia @ w))
    return np.concatenate([d, dd, (wheel_vel(a) @ d)[:2]])


def wheel_energy(a: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Kinetic plus potential energy along columns of angles and der_angles."""
    out = []
    for ak, dk in zip(a.T, d.T):
        w, v = wheel_jac(ak) @ dk, wheel_vel(ak) @ dk
        out.append(0.5 * WHEEL_MASS * v @ v + 0.5 * w @ WHEEL_INERTIA @ w
                   - WHEEL_MASS * G_N * wheel_delta(ak)[2])
    return np.array(out)


def rolling_wheel(refs: Path) -> None:
    """Parts.RollingWheel: radius 0.3, m 2, I diag(0.12, 0.06, 0.12); angles {3,2,1}."""
    grid, col = reference(refs, "RollingWheel")
    y = solve(wheel_rhs, np.array([0, 0, 0, 0, 5, 1, 0.2, 0.2], float), 4.0, grid)
    names = [f"wheel1.angles[{i}]" for i in (1, 2, 3)] + \
        [f"wheel1.der_angles[{i}]" for i in (1, 2, 3)] + ["wheel1.x", "wheel1.y"]
    ref = np.array([col(n) for n in names])
    report("RollingWheel", grid, wheel_energy(y[:3], y[3:6]), wheel_energy(ref[:3], ref[3:6]),
           dict(zip(names, y)), col)
    np.save("/tmp/truth-RollingWheel.npy", np.vstack([grid, y]))


def double_pendulum(refs: Path) -> None:
    """Two BodyBox links (0.5 x 0.06 x 0.06 steel), damper d = 0.1 on joint 1, gravity -y."""
    length, d = 0.5, 0.1
    m = 7700.0 * length * 0.06 * 0.06
    j = m / 12 * (length**2 + 0.06**2)
    a1, a2, a3 = m * length**2 / 4 + j, m * length**2 / 4 + j, m * length**2 / 2

    def mass(q2: float) -> np.ndarray:  # coordinates phi1, phi2 (relative)
        c = a3 * np.cos(q2)
        return np.array([[a1 + m * length**2 + a2 + 2 * c, a2 + c], [a2 + c, a2]])

    def rhs(_t: float, s: np.ndarray) -> np.ndarray:
        q1, q2, u1, u2 = s[:4]
        h = a3 * np.sin(q2)
        th1, th2 = q1, q1 + q2
        g1 = -m * G_N * length * (1.5 * np.cos(th1) + 0.5 * np.cos(th2))
        g2 = -m * G_N * length * 0.5 * np.cos(th2)
        force = np.array([h * (2 * u1 * u2 + u2**2) + g1 - d * u1, -h * u1**2 + g2])
        acc = np.linalg.solve(mass(q2), force)
        return np.array([u1, u2, acc[0], acc[1], d * u1**2])

    def energy(q1: np.ndarray, q2: np.ndarray, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
        kin = np.array([0.5 * u @ mass(b) @ u for b, u in zip(q2, np.column_stack([u1, u2]))])
        th2 = q1 + q2
        return kin + m * G_N * length * (1.5 * np.sin(q1) + 0.5 * np.sin(th2))

    grid, col = reference(refs, "DoublePendulumInitTip")
    names = ["revolute1.phi", "revolute2.phi", "revolute1.w", "revolute2.w"]
    s0 = np.array([col(n)[0] for n in names] + [0.0])
    tip = length * np.array([np.cos(s0[0]) + np.cos(s0[0] + s0[1]),
                             np.sin(s0[0]) + np.sin(s0[0] + s0[1])])
    print(f"  the reference's first row puts the tip at ({tip[0]:.12f}, {tip[1]:.12f})")
    t, keep = np.unique(grid, return_index=True)  # the reference writes one time twice
    y = solve(rhs, s0, 5.0, t)
    ref = [col(n)[keep] for n in names]
    step = np.diff(t)
    ref_lost = np.concatenate([[0.0], np.cumsum(0.5 * step * d * (ref[2][1:]**2 + ref[2][:-1]**2))])
    own_lost = np.concatenate([[0.0], np.cumsum(0.5 * step * d * (y[2][1:]**2 + y[2][:-1]**2))])
    print(f"  trapezoid dissipation on the grid, independent run: balance drift "
          f"{np.abs(energy(*y[:4]) + own_lost - energy(*y[:4])[0]).max():.2e} (the quadrature)")
    report("DoublePendulumInitTip", t, energy(*y[:4]) + y[4], energy(*ref) + ref_lost,
           dict(zip(names, y)), lambda n: col(n)[keep])
    np.save("/tmp/truth-DoublePendulumInitTip.npy", np.vstack([t, y]))


def point_masses(refs: Path, name: str) -> None:
    """Point masses in a point gravity field (mu 1); with masses, bodies 3, 4 on a spring."""
    if name == "PointGravity":
        r0, v0, spring, stop = [[0, .6, 0], [.6, .6, 0]], [[1, 0, 0], [.6, 0, 0]], None, 5.0

        def signal(b: int, q: str, i: int) -> str:
            return f"body{b}.frame_a.r_0[{i}]" if q == "r" else f"body{b}.v_0[{i}]"
    else:
        r0 = [[0, .6, 0], [.6, .6, 0], [0, .8, 0], [.3, .8, 0]]
        v0, spring, stop = [[1, 0, 0], [.6, 0, 0], [.6, 0, 0], [.6, 0, 0]], 10.0, 2.0

        def signal(b: int, q: str, i: int) -> str:
            return f"body{b}.{q}_0[{i}]"
    n = len(r0)

    def rhs(_t: float, s: np.ndarray) -> np.ndarray:
        r = s[:3 * n].reshape(n, 3)
        a = -r / np.linalg.norm(r, axis=1)[:, None]**3
        if spring:
            a[2] += spring * (r[3] - r[2])
            a[3] -= spring * (r[3] - r[2])
        return np.concatenate([s[3 * n:], a.ravel()])

    def energy(s: np.ndarray) -> np.ndarray:
        r, v = s[:3 * n].reshape(n, 3, -1), s[3 * n:].reshape(n, 3, -1)
        e = (0.5 * (v**2).sum(1) - 1 / np.sqrt((r**2).sum(1))).sum(0)
        return e + (0.5 * spring * ((r[3] - r[2])**2).sum(0) if spring else 0.0)

    grid, col = reference(refs, name)
    y = solve(rhs, np.concatenate([np.ravel(r0), np.ravel(v0)]), stop, grid)
    names = [signal(b, q, i) for q in "rv" for b in range(1, n + 1) for i in (1, 2, 3)]
    ref = np.array([col(s) for s in names])
    report(name, grid, energy(y), energy(ref), dict(zip(names, y)), col)
    for b in range(n):
        dist = np.linalg.norm(y[3 * b:3 * b + 3], axis=0)
        print(f"  body{b + 1} passes {dist.min():.4f} m from the centre at "
              f"t = {grid[dist.argmin()]:.4f}")
    np.save(f"/tmp/truth-{name}.npy", np.vstack([grid, y]))


def rigid_point_masses(refs: Path) -> None:
    """Six unit point masses at +-1 on the body axes (inertia 4 I), mu 5; state c, v, q, w_a."""
    offsets = np.vstack([E1, -E1, E2, -E2, E3, -E3])

    def body_to_world(q: np.ndarray) -> np.ndarray:
        w, x, y, z = q
        return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])

    def rhs(_t: float, s: np.ndarray) -> np.ndarray:
        c, v, q, w = s[:3], s[3:6], s[6:10], s[10:13]
        a = body_to_world(q)
        x = c + offsets @ a.T
        f = -5.0 * x / np.linalg.norm(x, axis=1)[:, None]**3
        qdot = 0.5 * np.concatenate([[-q[1:] @ w], q[0] * w + np.cross(q[1:], w)])
        return np.concatenate([v, f.sum(0) / 6, qdot, a.T @ np.cross(x - c, f).sum(0) / 4])

    grid, col = reference(refs, "PointGravityWithPointMasses2")
    y = solve(rhs, np.array([2, 0, 0, 0, 0, -1, 1, 0, 0, 0, 0, 0, 0], float), 3.0, grid)
    rot_ = np.array([body_to_world(q) for q in y[6:10].T])
    spin = np.einsum("kij,jk->ki", rot_, y[10:13])
    r6, v = y[:3].T - rot_[:, :, 2], y[3:6].T
    ours = {f"freeMotion.r_rel_a[{i + 1}]": y[i] for i in range(3)}
    ours |= {f"freeMotion.v_rel_a[{i + 1}]": y[3 + i] for i in range(3)}
    ours |= {f"referenceSystem.pointMass1.w_a[{i + 1}]": y[10 + i] for i in range(3)}
    ours |= {f"referenceSystem.pointMass6.frame_a.r_0[{i + 1}]": r6[:, i] for i in range(3)}
    ours["referenceSystem.pointMass6.v_0[2]"] = (v - np.cross(spin, rot_[:, :, 2]))[:, 1]
    ours["referenceSystem.pointMass6.v_0[3]"] = (v - np.cross(spin, rot_[:, :, 2]))[:, 2]
    ours["referenceSystem.pointMass3.v_0[1]"] = (v + np.cross(spin, rot_[:, :, 1]))[:, 0]

    def energy(c: np.ndarray, v: np.ndarray, w: np.ndarray, axes: list[np.ndarray]) -> np.ndarray:
        pot = sum(1 / np.linalg.norm(c + sign * e, axis=1) for e in axes for sign in (1, -1))
        return 3 * (v**2).sum(1) + 2 * (w**2).sum(1) - 5.0 * pot

    own = energy(y[:3].T, v, y[10:13].T, [rot_[:, :, k] for k in range(3)])
    # the reference turns about the body's y axis only: its axes from pointMass6's position
    c = np.array([col(f"freeMotion.r_rel_a[{i}]") for i in (1, 2, 3)]).T
    e3 = c - np.array([col(f"referenceSystem.pointMass6.frame_a.r_0[{i}]") for i in (1, 2, 3)]).T
    e1 = np.column_stack([e3[:, 2], 0 * e3[:, 0], -e3[:, 0]])
    theirs = energy(c, np.array([col(f"freeMotion.v_rel_a[{i}]") for i in (1, 2, 3)]).T,
                    np.array([col(f"referenceSystem.pointMass1.w_a[{i}]") for i in (1, 2, 3)]).T,
                    [e1, np.tile(E2, (len(grid), 1)), e3])
    report("PointGravityWithPointMasses2", grid, own, theirs, ours, col)
    x = y[:3].T[:, None, :] + np.einsum("kij,pj->kpi", rot_, offsets)
    k, p = np.unravel_index(np.linalg.norm(x, axis=2).argmin(), x.shape[:2])
    print(f"  point mass {p + 1} passes {np.linalg.norm(x[k, p]):.4f} m from the centre at "
          f"t = {grid[k]:.4f}")
    np.save("/tmp/truth-PointGravityWithPointMasses2.npy", np.vstack([grid, y]))


def force_and_torque(refs: Path) -> None:
    """BodyCylinder (1 m, diameter 0.05, steel) on revolute z then y at (0, -0.5, 0); the
    force {0, 1000, 0} at its tip and the torque {-100, 100, 0}, both in a frame turned
    30 degrees about z; Lagrange's equations by sympy, the applied loads as generalized
    forces. The constant torque makes no invariant: the check is the two methods."""
    import sympy

    q1, q2, u1, u2 = sympy.symbols("q1 q2 u1 u2")
    rz = sympy.Matrix([[sympy.cos(q1), -sympy.sin(q1), 0], [sympy.sin(q1), sympy.cos(q1), 0],
                       [0, 0, 1]])
    ry = sympy.Matrix([[sympy.cos(q2), 0, sympy.sin(q2)], [0, 1, 0],
                       [-sympy.sin(q2), 0, sympy.cos(q2)]])
    m = 7700.0 * np.pi * 0.025**2
    inertia = sympy.diag(m * 0.025**2 / 2, m * (1 / 12 + 0.025**2 / 4), m * (1 / 12 + 0.025**2 / 4))
    q, u, axis = sympy.Matrix([q1, q2]), sympy.Matrix([u1, u2]), rz * ry * sympy.Matrix([1, 0, 0])
    centre, tip = sympy.Matrix([0, -0.5, 0]) + axis / 2, sympy.Matrix([0, -0.5, 0]) + axis
    w0 = sympy.Matrix([0, 0, u1]) + rz * sympy.Matrix([0, u2, 0])
    wb, vc = (rz * ry).T * w0, centre.jacobian(q) * u
    kinetic = m / 2 * vc.dot(vc) + (wb.T * inertia * wb)[0] / 2
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    force = sympy.Matrix([-1000 * s, 1000 * c, 0])
    torque = sympy.Matrix([-100 * (c + s), 100 * (c - s), 0])
    applied = tip.jacobian(q).T * force + w0.jacobian(u).T * torque \
        - sympy.Matrix([m * G_N * centre[1]]).jacobian(q).T
    energy = sympy.Matrix([kinetic])
    rest = energy.jacobian(u).T.jacobian(q) * u - energy.jacobian(q).T
    mass = sympy.lambdify((q1, q2), sympy.hessian(kinetic, u), "numpy")
    right = sympy.lambdify((q1, q2, u1, u2), applied - rest, "numpy")

    def rhs(_t: float, z: np.ndarray) -> np.ndarray:
        acc = np.linalg.solve(np.array(mass(z[0], z[1]), float),
                              np.array(right(*z), float).ravel())
        return np.array([z[2], z[3], acc[0], acc[1]])

    grid, col = reference(refs, "ForceAndTorque")
    y = solve(rhs, np.zeros(4), float(grid[-1]), grid)
    names = ["revolute1.phi", "revolute2.phi", "revolute1.w", "revolute2.w"]
    report("ForceAndTorque", grid, np.zeros(1), np.zeros(1), dict(zip(names, y)), col)
    np.save("/tmp/truth-ForceAndTorque.npy", np.vstack([grid, y]))


EXAMPLES: dict[str, Callable[[Path], None]] = {
    "RollingWheel": rolling_wheel,
    "DoublePendulumInitTip": double_pendulum,
    "ForceAndTorque": force_and_torque,
    "PointGravity": lambda refs: point_masses(refs, "PointGravity"),
    "PointGravityWithPointMasses": lambda refs: point_masses(refs, "PointGravityWithPointMasses"),
    "PointGravityWithPointMasses2": rigid_point_masses,
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--refs", type=Path, required=True)
    parser.add_argument("examples", nargs="*", default=list(EXAMPLES), choices=list(EXAMPLES))
    args = parser.parse_args(argv)
    for name in args.examples:
        print(name, flush=True)
        EXAMPLES[name](args.refs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
