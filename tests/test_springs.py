"""Mass–spring systems: integrators against SciPy's DOP853, energy behaviour, cloth, ropes, soft bodies, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from frustum.errors import SimulationError
from frustum.geometry.primitives import icosphere
from frustum.simulation import INTEGRATORS, MassSpringSystem, PlaneCollider, SphereCollider, cloth, rope, soft_body

# A small chain hung from a pinned anchor: 4 masses, 3 springs, damping, drag and gravity (3-D motion).
POSITIONS = np.array([[0.0, 0.0, 0.0], [0.3, -0.9, 0.1], [0.5, -2.1, -0.2], [1.1, -2.9, 0.3]])
MASSES = np.array([1.0, 1.0, 2.0, 0.5])
SPRINGS = np.array([[0, 1], [1, 2], [2, 3]])
STIFFNESS = np.array([40.0, 60.0, 30.0])
DAMPING = np.array([0.2, 0.1, 0.3])
REST = np.array([0.8, 1.0, 0.9])
GRAVITY = np.array([0.0, -9.81, 0.0])
DRAG = 0.05


def reference_derivative(_t: float, y: np.ndarray) -> np.ndarray:
    """ẏ for y = (x, v), written out spring by spring (independent of frustum's vectorized forces)."""
    x, v = y[:12].reshape(4, 3), y[12:].reshape(4, 3)
    force = MASSES[:, None] * (GRAVITY - DRAG * v)
    for (i, j), k, c, rest in zip(SPRINGS, STIFFNESS, DAMPING, REST, strict=True):
        d = x[j] - x[i]
        length = math.sqrt(d @ d)
        u = d / length
        f = (k * (length - rest) + c * ((v[j] - v[i]) @ u)) * u
        force[i] += f
        force[j] -= f
    acceleration = force / MASSES[:, None]
    acceleration[0] = 0.0
    velocity = v.copy()
    velocity[0] = 0.0
    return np.concatenate([velocity.ravel(), acceleration.ravel()])


def chain(integrator: str) -> MassSpringSystem:
    return MassSpringSystem(
        POSITIONS, MASSES, SPRINGS, stiffness=STIFFNESS, damping=DAMPING, rest_lengths=REST, pinned=[0],
        gravity=GRAVITY, integrator=integrator, drag=DRAG,
    )  # fmt: skip


@pytest.fixture(scope="module")
def reference_end_state() -> np.ndarray:
    y0 = np.concatenate([POSITIONS.ravel(), np.zeros(12)])
    solution = solve_ivp(reference_derivative, (0.0, 1.0), y0, method="DOP853", rtol=1e-10, atol=1e-12)
    assert solution.success
    return solution.y[:, -1]


ORDERS = {"explicit-euler": 1, "symplectic-euler": 1, "verlet": 2, "rk4": 4, "implicit-euler": 1}
STEPS = {"explicit-euler": (400, 800), "symplectic-euler": (400, 800), "verlet": (100, 200), "rk4": (50, 100),
         "implicit-euler": (400, 800)}  # fmt: skip


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_integrator_converges_to_dop853_with_its_order(integrator, reference_end_state):
    errors = []
    for steps in STEPS[integrator]:
        system = chain(integrator)
        for _ in range(steps):
            system.step(1.0 / steps)
        state = np.concatenate([system.positions.ravel(), system.velocities.ravel()])
        errors.append(np.abs(state - reference_end_state).max())
    # the errors sit far above the reference's (rtol 1e-10): each is > 1e-7
    assert min(errors) > 1e-7
    order = math.log2(errors[0] / errors[1])
    # observed order within ±0.3 of the theoretical one (the step counts are in the asymptotic range)
    assert abs(order - ORDERS[integrator]) < 0.3, (integrator, errors, order)
    # and the finer step is close to the reference: tolerance per order
    assert errors[1] < {1: 0.05, 2: 5e-3, 4: 1e-4}[ORDERS[integrator]]


def spring_line(integrator: str) -> MassSpringSystem:
    """Ten masses on a line joined by springs (k = 100, m = 1), the first pinned, the rest displaced."""
    positions = np.stack([np.arange(10.0), np.zeros(10), np.zeros(10)], axis=1)
    springs = np.stack([np.arange(9), np.arange(1, 10)], axis=1)
    system = MassSpringSystem(positions, 1.0, springs, stiffness=100.0, pinned=[0], integrator=integrator)
    system._x[1:, 1] = 0.1 * np.sin(np.arange(1, 10) * 0.4)  # a transverse pluck (rest lengths stay 1)
    system._x[1:, 0] += 0.05 * np.cos(np.arange(1, 10))
    return system


@pytest.mark.parametrize(("integrator", "bound"), [("symplectic-euler", 0.1), ("verlet", 0.01)])
def test_symplectic_integrators_keep_the_energy_bounded_over_ten_thousand_steps(integrator, bound):
    system = spring_line(integrator)
    initial = system.energy()
    assert initial > 0.0
    worst = 0.0
    for _ in range(10_000):
        system.step(0.01)  # h·ω_max ≈ 0.01·20 = 0.2 (stable region: < 2)
        worst = max(worst, abs(system.energy() - initial))
    # symplectic Euler's energy error is O(h) and bounded (10 %); Verlet's is O(h²) (1 %)
    assert worst <= bound * initial


def test_explicit_euler_energy_grows_over_ten_thousand_steps():
    system = spring_line("explicit-euler")
    initial = system.energy()
    energies = []
    for _ in range(10_000):
        system.step(0.01)
        energies.append(system.energy())
    assert energies[-1] > 3.0 * initial  # each mode's energy grows by (1 + h²ω²) per step
    assert energies[-1] > energies[5000] > energies[1000] > initial


def stiff_pair(integrator: str) -> MassSpringSystem:
    system = MassSpringSystem([[0, 0, 0], [1.2, 0, 0]], 1.0, [[0, 1]], stiffness=1e4, rest_lengths=[1.0],
                              pinned=[0], integrator=integrator)  # fmt: skip
    return system


def test_implicit_euler_is_stable_where_explicit_euler_diverges():
    dt = 0.05  # h·ω = 0.05·100 = 5: outside every explicit method's stability region
    explicit = stiff_pair("explicit-euler")
    with pytest.raises(SimulationError, match=r"after step \d+ .*dt = 0.05.*'explicit-euler'.*smaller dt.*"
                                              r"implicit-euler"):  # fmt: skip
        for _ in range(2000):
            explicit.step(dt)
    assert explicit.steps > 100  # it grew for a while before overflowing
    implicit = stiff_pair("implicit-euler")
    initial = implicit.energy()
    energies = []
    for _ in range(2000):
        implicit.step(dt)
        energies.append(implicit.energy())
    assert max(energies) <= initial * (1 + 1e-9)  # backward Euler only dissipates
    assert energies[-1] < 1e-3 * initial  # and settles at rest
    np.testing.assert_allclose(np.linalg.norm(implicit.positions[1]), 1.0, atol=1e-3)


def test_forces_are_minus_the_gradient_of_the_spring_and_gravity_energy():
    rng = np.random.default_rng(0)
    positions = rng.normal(size=(6, 3))
    springs = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [0, 5], [1, 4]])
    system = MassSpringSystem(positions, rng.uniform(0.5, 2.0, 6), springs, stiffness=rng.uniform(1, 50, 7),
                              rest_lengths=rng.uniform(0.5, 1.5, 7), gravity=(0.0, -9.81, 1.0))  # fmt: skip
    forces = system.forces(system.positions, np.zeros((6, 3)))
    h = 1e-6
    for i in range(6):
        for c in range(3):
            system._x[i, c] += h
            up = system.energy()
            system._x[i, c] -= 2 * h
            down = system.energy()
            system._x[i, c] += h
            # central difference: error O(h²·E''') plus round-off ~1e-16·E/h
            assert forces[i, c] == pytest.approx(-(up - down) / (2 * h), abs=1e-6)


def test_cloth_has_structural_shear_and_bend_springs_and_faces_up():
    nx, ny = 6, 4
    system = cloth(2.0, 1.0, nx, ny, center=(0, 1, 0))
    structural = (nx - 1) * ny + nx * (ny - 1)
    shear = 2 * (nx - 1) * (ny - 1)
    bend = (nx - 2) * ny + nx * (ny - 2)
    assert system.springs.shape == (structural + shear + bend, 2)
    assert system.count == nx * ny
    np.testing.assert_allclose(system.masses.sum(), 1.0)
    mesh = system.mesh
    assert mesh.face_count == 2 * (nx - 1) * (ny - 1)
    np.testing.assert_allclose(mesh.face_normals, np.tile([0, 1.0, 0], (mesh.face_count, 1)), atol=1e-12)
    np.testing.assert_allclose(mesh.bounds, [[-1, 1, -0.5], [1, 1, 0.5]])
    hanging = cloth(1.0, 1.0, 3, 3, plane="xy")
    np.testing.assert_allclose(hanging.mesh.face_normals[:, 2], 1.0)


def test_pinned_corners_stay_put_and_the_cloth_sags():
    system = cloth(1.0, 1.0, 8, 8, pinned=[0, 7], gravity=(0, -9.81, 0), integrator="implicit-euler",
                   stiffness=800.0)  # fmt: skip
    corners = system.positions[[0, 7]].copy()
    for _ in range(30):
        system.step(1 / 60)
    np.testing.assert_array_equal(system.positions[[0, 7]], corners)
    assert system.positions[:, 1].min() < -0.2
    assert np.isfinite(system.mesh.vertex_normals).all()


def test_cloth_drapes_over_a_sphere_without_entering_it():
    ball = SphereCollider((0, 0, 0), 0.5, restitution=0.0, friction=0.5)
    floor = PlaneCollider((0, -1, 0))
    system = cloth(2.0, 2.0, 12, 12, center=(0, 0.6, 0), gravity=(0, -9.81, 0), colliders=[ball, floor],
                   integrator="implicit-euler", stiffness=400.0, drag=0.05)  # fmt: skip
    for _ in range(60):
        system.step(1 / 60)
        assert np.linalg.norm(system.positions, axis=1).min() >= 0.5 - 1e-12
        assert system.positions[:, 1].min() >= -1 - 1e-12
    centre = system.positions[(12 * 12) // 2 + 6]
    assert abs(np.linalg.norm(centre) - 0.5) < 0.05  # resting on top of the ball
    assert system.positions[0, 1] < 0.0  # the corners fell past the ball's equator


def test_rope_and_soft_body_build_and_step():
    hanging = rope((0, 0, 0), (2, 0, 0), 11, pinned=[0], gravity=(0, -9.81, 0), bend_stiffness=10.0)
    assert hanging.springs.shape == (10 + 9, 2)
    for _ in range(100):
        hanging.step(1 / 200)
    assert hanging.positions[-1, 1] < -0.1 and (hanging.positions[0] == 0).all()
    body = soft_body(icosphere(1.0, 1), stiffness=200.0, gravity=(0, -9.81, 0), colliders=[PlaneCollider((0, -1, 0))])
    mesh = body.mesh
    assert mesh.is_watertight and body.springs.shape[0] == mesh.edges.shape[0] + mesh.edges.shape[0]
    volume = mesh.volume
    for _ in range(120):
        body.step(1 / 240)
    assert body.positions[:, 1].min() >= -1 - 1e-12
    assert 0.5 * volume < body.mesh.volume < 1.5 * volume  # squashed by the fall, not collapsed


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"masses": [1.0, -2.0, 1.0]}, r"masses\[1\] = -2.0 is not positive"),
        ({"masses": 0.0}, r"masses = 0.0 is not positive"),
        ({"stiffness": -5.0}, r"stiffness = -5.0 is negative"),
        ({"stiffness": [1.0, -1.0]}, r"stiffness\[1\] = -1.0 is negative"),
        ({"damping": -0.1}, r"damping = -0.1 is negative"),
        ({"springs": [[0, 1], [1, 3]]}, r"springs\[1\] = \[1, 3\] names a missing point"),
        ({"springs": [[0, 1], [2, 2]]}, r"springs\[1\] = \[2, 2\] joins a point to itself"),
        ({"springs": [[0.0, 1.0]]}, r"springs has dtype float64"),
        ({"integrator": "leapfrog"}, r"integrator = 'leapfrog' is unknown; expected one of 'explicit-euler'"),
        ({"pinned": [5]}, r"pinned\[0\] = 5 names a missing point"),
        ({"rest_lengths": [1.0]}, r"rest_lengths has shape \(1,\)"),
        ({"positions": [[0, 0, 0], [np.nan, 0, 0], [2, 0, 0]]}, r"positions\[1\] = .* is not finite"),
    ],
)
def test_bad_input_raises_simulation_error(kwargs, match):
    arguments = {"positions": [[0, 0, 0], [1, 0, 0], [2, 0, 0]], "masses": 1.0, "springs": [[0, 1], [1, 2]],
                 "stiffness": 10.0}  # fmt: skip
    arguments.update(kwargs)
    positions, masses, springs = arguments.pop("positions"), arguments.pop("masses"), arguments.pop("springs")
    with pytest.raises(SimulationError, match=match):
        MassSpringSystem(positions, masses, springs, **arguments)


@pytest.mark.parametrize("dt", [0.0, -1.0, float("inf")])
def test_step_rejects_a_bad_time_step(dt):
    with pytest.raises(SimulationError, match=r"dt = "):
        chain("rk4").step(dt)


def test_cloth_rejects_bad_sizes():
    with pytest.raises(SimulationError, match=r"nx = 1 is below 2"):
        cloth(1.0, 1.0, 1, 5)
    with pytest.raises(SimulationError, match=r"width, height = -1.0, 1.0 must be > 0"):
        cloth(-1.0, 1.0, 3, 3)
    with pytest.raises(SimulationError, match=r"no faces"):
        rope((0, 0, 0), (1, 0, 0), 3).mesh  # noqa: B018
