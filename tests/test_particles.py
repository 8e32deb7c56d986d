"""Particle systems (Reeves): motion, lifetime, generation statistics, collisions, emitters, ramps, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum.errors import SimulationError
from frustum.geometry import Mesh
from frustum.simulation import (
    Attractor,
    DiskEmitter,
    Drag,
    Gravity,
    LineEmitter,
    MeshEmitter,
    ParticleSystem,
    PlaneCollider,
    PointEmitter,
    SphereCollider,
    SphereEmitter,
    Vortex,
    Wind,
)


def test_particle_under_gravity_follows_the_parabola_with_symplectic_eulers_known_term():
    g = np.array([0.0, -9.81, 0.0])
    x0, d, speed = np.array([1.0, 2.0, -0.5]), np.array([1.0, 2.0, 0.5]), 3.0
    system = ParticleSystem(
        emitter=PointEmitter(x0, direction=d, spread=0.0, speed=speed), rate=0.0, lifetime=100.0,
        forces=[Gravity(g)], seed=3,
    )  # fmt: skip
    system.emit(1)
    v0 = speed * d / np.linalg.norm(d)
    dt = 0.01
    for n in range(1, 201):
        system.step(dt)
        t = n * dt
        # semi-implicit Euler under constant g: x_n = x0 + v0 t + g t²/2 + g dt t/2 (exact up to round-off)
        expected = x0 + v0 * t + 0.5 * g * t * t + 0.5 * g * dt * t
        np.testing.assert_allclose(system.positions[0], expected, rtol=0, atol=1e-11)
        np.testing.assert_allclose(system.velocities[0], v0 + g * t, rtol=0, atol=1e-11)
    # and the analytic parabola within the stated first-order term |g|·dt·t/2
    assert np.linalg.norm(system.positions[0] - (x0 + v0 * t + 0.5 * g * t * t)) <= 9.81 * dt * t / 2 + 1e-9


def test_lifetime_removal_is_exact():
    dt = 0.125  # a binary fraction: ages add up exactly
    system = ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=8.0, lifetime=1.0, seed=0)
    counts = []
    for _ in range(20):
        system.step(dt)
        counts.append(system.count)
        assert (system.ages < 1.0).all()
    # one particle is born per step (rate·dt = 1 exactly) and lives exactly 8 steps
    assert counts == [min(k, 8) for k in range(1, 21)]
    burst = ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=0.0, lifetime=0.5, seed=0)
    burst.emit(7)
    for _ in range(3):
        burst.step(dt)
    assert burst.count == 7
    burst.step(dt)
    assert burst.count == 0


def test_counts_per_step_have_the_requested_mean_and_variance():
    # rate·dt = 50 ± 20 (Reeves' mean ± variance, U(−1, 1)), rounded stochastically: E[n] = 50 and
    # Var[n] = 20²/3 + 1/6 = 133.5 (the spread covers whole numbers evenly, so E[f(1 − f)] = 1/6).
    dt, steps = 0.125, 20000
    system = ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=400.0, rate_variance=160.0, lifetime=0.01, seed=7)
    counts = np.empty(steps)
    for k in range(steps):
        system.step(dt)  # lifetime < dt: every particle dies at the next step, so count = this step's births
        counts[k] = system.count
    # tolerances: about 5 standard errors at n = 20000 (mean: √(133.5/n) = 0.08; variance: 133.5·√(0.8/n) = 0.85)
    assert abs(counts.mean() - 50.0) < 0.4
    assert abs(counts.var() - 133.5) < 4.5
    assert counts.min() >= 30 and counts.max() <= 70


def test_same_seed_gives_the_same_bytes_and_another_seed_does_not():
    def run(seed: int) -> bytes:
        system = ParticleSystem(
            emitter=DiskEmitter((0, 0, 0), radius=0.5, spread=0.4, speed=2.0, speed_variance=0.5), rate=3000.0,
            lifetime=1.0, lifetime_variance=0.3, forces=[Gravity(), Drag(0.2), Vortex((0, 0, 0))], seed=seed,
            colliders=[PlaneCollider((0, -0.5, 0))],
        )  # fmt: skip
        for _ in range(30):
            system.step(1 / 30)
        return system.positions.tobytes() + system.velocities.tobytes() + system.ages.tobytes()

    assert run(11) == run(11)
    assert run(11) != run(12)


@settings(max_examples=25)
@given(
    restitution=st.floats(0.0, 1.0),
    friction=st.floats(0.0, 1.0),
    seed=st.integers(0, 2**31),
    speed=st.floats(0.1, 20.0),
)
def test_no_particle_ends_a_step_below_a_collision_plane(restitution, friction, seed, speed):
    normal = np.array([0.2, 1.0, -0.1])
    plane = PlaneCollider((0.0, -0.3, 0.0), normal, restitution=restitution, friction=friction)
    system = ParticleSystem(
        emitter=SphereEmitter((0, 0.5, 0), radius=0.3, speed=speed, spread=0.5), rate=600.0, lifetime=2.0,
        forces=[Gravity((0, -20.0, 0))], colliders=[plane], seed=seed,
    )  # fmt: skip
    unit = normal / np.linalg.norm(normal)
    for _ in range(40):
        system.step(0.02)
        distance = (system.positions - (0.0, -0.3, 0.0)) @ unit
        assert distance.min(initial=0.0) >= -1e-12  # only round-off of the mirror step


def test_no_particle_ends_a_step_inside_a_sphere_collider():
    ball = SphereCollider((0.0, 0.0, 0.0), 1.0, restitution=0.3, friction=0.2)
    system = ParticleSystem(
        emitter=PointEmitter((0, 3, 0), direction=(0, -1, 0), spread=0.3, speed=2.0), rate=500.0, lifetime=3.0,
        forces=[Gravity()], colliders=[ball], seed=2,
    )  # fmt: skip
    for _ in range(60):
        system.step(1 / 60)
        assert np.linalg.norm(system.positions, axis=1).min(initial=2.0) >= 1.0 - 1e-12


def test_restitution_one_keeps_the_speed():
    plane = PlaneCollider((0, 0, 0), (0, 1, 0), restitution=1.0, friction=0.0)
    system = ParticleSystem(
        emitter=PointEmitter((0, 1, 0), direction=(0.3, -1, 0.2), spread=0.6, speed=4.0, speed_variance=1.0),
        rate=0.0, lifetime=10.0, colliders=[plane], seed=5,
    )  # fmt: skip
    system.emit(200)
    speeds = np.linalg.norm(system.velocities, axis=1)
    bounced = np.zeros(200, dtype=bool)
    for _ in range(100):
        system.step(0.01)
        bounced |= system.velocities[:, 1] > 0
        np.testing.assert_allclose(np.linalg.norm(system.velocities, axis=1), speeds, rtol=1e-12)
    assert bounced.all()  # every particle hit the plane at least once
    # restitution 0.5 halves the normal speed
    half = ParticleSystem(emitter=PointEmitter((0, 0.05, 0), direction=(0, -1, 0), speed=10.0), rate=0.0,
                          lifetime=10.0, colliders=[PlaneCollider(restitution=0.5)], seed=0)  # fmt: skip
    half.emit(1)
    half.step(0.01)
    np.testing.assert_allclose(half.velocities[0], (0.0, 5.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(half.positions[0], (0.0, 0.025, 0.0), atol=1e-12)


@settings(max_examples=25)
@given(spread=st.floats(0.0, math.pi), seed=st.integers(0, 2**31))
def test_emitted_directions_lie_in_the_spread_cone(spread, seed):
    axis = np.array([0.3, -0.4, 0.8])
    system = ParticleSystem(emitter=PointEmitter((0, 0, 0), direction=axis, spread=spread, speed=2.0), rate=0.0,
                            lifetime=1.0, seed=seed)  # fmt: skip
    system.emit(500)
    directions = system.velocities / 2.0
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0, atol=1e-12)
    cosines = directions @ (axis / np.linalg.norm(axis))
    assert cosines.min() >= math.cos(spread) - 1e-12


def test_cone_directions_are_area_uniform_on_the_cap():
    # uniform on the cap: cos θ is uniform on [cos spread, 1], so its mean is (1 + cos spread)/2
    spread = 1.0
    system = ParticleSystem(emitter=PointEmitter((0, 0, 0), direction=(0, 0, 1), spread=spread), rate=0.0,
                            lifetime=1.0, seed=9)  # fmt: skip
    system.emit(40000)
    cosines = system.velocities[:, 2]
    # standard error (1 − cos 1)/√12/√40000 ≈ 6.6e-4; 5 of them
    assert abs(cosines.mean() - (1 + math.cos(spread)) / 2) < 3.3e-3
    assert abs(np.arctan2(system.velocities[:, 1], system.velocities[:, 0]).mean()) < 0.05


def test_emitters_place_particles_on_their_shapes():
    rng_seed = 4
    disk = ParticleSystem(emitter=DiskEmitter((1, 2, 3), normal=(0, 0, 1), radius=0.5), rate=0, lifetime=1,
                          seed=rng_seed)  # fmt: skip
    disk.emit(1000)
    offsets = disk.positions - (1, 2, 3)
    assert np.abs(offsets[:, 2]).max() < 1e-12 and np.linalg.norm(offsets, axis=1).max() <= 0.5 + 1e-12
    np.testing.assert_allclose(disk.velocities, np.tile([0, 0, 1.0], (1000, 1)), atol=1e-12)
    sphere = ParticleSystem(emitter=SphereEmitter((0, 1, 0), radius=2.0, speed=1.0), rate=0, lifetime=1, seed=1)
    sphere.emit(1000)
    offsets = sphere.positions - (0, 1, 0)
    np.testing.assert_allclose(np.linalg.norm(offsets, axis=1), 2.0, atol=1e-12)
    np.testing.assert_allclose(sphere.velocities, offsets / 2.0, atol=1e-12)  # outward normals
    line = ParticleSystem(emitter=LineEmitter((0, 0, 0), (2, 0, 0)), rate=0, lifetime=1, seed=1)
    line.emit(1000)
    assert np.abs(line.positions[:, 1:]).max() == 0 and line.positions[:, 0].min() >= 0
    assert line.positions[:, 0].max() <= 2
    # a mesh: two unit triangles of the plane z = 0 (area 0.5 and 1.5), normals +z
    mesh = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [3, 0, 0], [4, 0, 0], [3, 3, 0]], [[0, 1, 2], [3, 4, 5]])
    surface = ParticleSystem(emitter=MeshEmitter(mesh, speed=1.0), rate=0, lifetime=1, seed=2)
    surface.emit(20000)
    assert np.abs(surface.positions[:, 2]).max() == 0
    np.testing.assert_allclose(surface.velocities, np.tile([0, 0, 1.0], (20000, 1)), atol=1e-12)
    on_second = (surface.positions[:, 0] >= 3).mean()
    assert abs(on_second - 0.75) < 0.02  # ∝ area: 1.5 / 2; standard error 0.003
    first = surface.positions[surface.positions[:, 0] < 3]
    assert (first[:, 0] + first[:, 1] <= 1 + 1e-12).all() and (first >= -1e-12).all()


def test_forces_give_their_formulas():
    x = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 1.0]])
    v = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    np.testing.assert_allclose(Drag(0.5).acceleration(x, v), -0.5 * v)
    np.testing.assert_allclose(Wind((2, 0, 0), 0.5).acceleration(x, v), 0.5 * (np.array([2.0, 0, 0]) - v))
    vortex = Vortex((0, 0, 0), (0, 0, 1), strength=2.0, core=0.5).acceleration(x, v)
    np.testing.assert_allclose(vortex[0], 2.0 * np.array([0.0, 1.0, 0.0]) / (1.0 + 0.25))
    np.testing.assert_allclose(vortex[1], 2.0 * np.array([-2.0, 0.0, 0.0]) / (4.0 + 0.25))
    pull = Attractor((0, 0, 0), strength=3.0, softening=1.0).acceleration(x, v)
    np.testing.assert_allclose(pull[0], 3.0 * np.array([-1.0, 0, 0]) / 2.0**1.5)


def test_ramps_interpolate_over_normalized_age():
    system = ParticleSystem(
        emitter=PointEmitter((0, 0, 0)), rate=0.0, lifetime=1.0, seed=0,
        color=[(0.0, (1.0, 1.0, 0.0)), (0.5, (1.0, 0.0, 0.0)), (1.0, (0.0, 0.0, 0.0))],
        size=[(0.0, 0.1), (1.0, 0.3)], opacity=0.5,
    )  # fmt: skip
    system.emit(1)
    system.step(0.25)
    np.testing.assert_allclose(system.colors[0], (1.0, 0.5, 0.0))
    np.testing.assert_allclose(system.sizes[0], 0.15)
    np.testing.assert_allclose(system.opacities[0], 0.5)
    system.step(0.5)
    np.testing.assert_allclose(system.colors[0], (0.5, 0.0, 0.0))


def test_particles_outside_the_region_die():
    system = ParticleSystem(emitter=PointEmitter((0, 0, 0), direction=(1, 0, 0), speed=1.0), rate=0.0,
                            lifetime=10.0, region=((-1, -1, -1), (1, 1, 1)), seed=0)  # fmt: skip
    system.emit(3)
    for _ in range(10):
        system.step(0.1)
    assert system.count == 3
    system.step(0.1)
    assert system.count == 0


def test_positions_are_read_only_views():
    system = ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=0.0, lifetime=1.0, seed=0)
    system.emit(2)
    with pytest.raises(ValueError):
        system.positions[0, 0] = 1.0
    assert system.positions.shape == (2, 3) and system.velocities.shape == (2, 3)


def test_a_million_particles_step_without_a_python_loop():
    system = ParticleSystem(
        emitter=PointEmitter((0, 0, 0), spread=0.5, speed=5.0), rate=0.0, lifetime=5.0,
        forces=[Gravity(), Drag(0.1)], colliders=[PlaneCollider()], seed=1,
    )  # fmt: skip
    system.emit(1_000_000)
    system.step(0.01)
    assert system.count == 1_000_000 and system.positions[:, 1].min() >= 0.0


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=-1.0, lifetime=1.0), r"rate = -1.0 is negative"),
        (lambda: ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=1.0, lifetime=0.0), r"lifetime = 0.0 is not"),
        (lambda: ParticleSystem(emitter=(0, 0, 0), rate=1.0, lifetime=1.0), r"emitter = .* is not an emitter"),
        (lambda: ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=1.0, lifetime=1.0, forces=[9.8]),
         r"forces = .* is not a list of forces"),
        (lambda: PointEmitter((0, 0, 0), spread=4.0), r"spread = 4.0 is above pi"),
        (lambda: PointEmitter((0, 0, 0), direction=(0, 0, 0)), r"direction = .* has zero length"),
        (lambda: PlaneCollider(restitution=1.5), r"restitution = 1.5 is above 1"),
        (lambda: ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=1.0, lifetime=1.0, lifetime_variance=1.0),
         r"lifetime_variance = 1.0 is not below lifetime"),
        (lambda: ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=1.0, lifetime=1.0,
                                color=[(0.5, (1, 0, 0)), (0.2, (0, 1, 0))]), r"color ramp times .* not increasing"),
        (lambda: ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=1.0, lifetime=1.0, opacity=2.0),
         r"opacity = .* outside \[0, 1\]"),
        (lambda: ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=1.0, lifetime=1.0, seed=-3),
         r"seed = -3 is below 0"),
    ],
)  # fmt: skip
def test_bad_input_raises_simulation_error(build, match):
    with pytest.raises(SimulationError, match=match):
        build()


@pytest.mark.parametrize("dt", [0.0, -0.1, float("nan")])
def test_step_rejects_a_non_positive_time_step(dt):
    system = ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=1.0, lifetime=1.0)
    with pytest.raises(SimulationError, match=r"dt = "):
        system.step(dt)


def test_a_blow_up_names_the_step():
    system = ParticleSystem(emitter=PointEmitter((0, 0, 0), speed=1.0), rate=0.0, lifetime=100.0,
                            forces=[Gravity((0, 1e307, 0))], seed=0)  # fmt: skip
    system.emit(1)
    with pytest.raises(SimulationError, match=r"not finite .* after step \d+ .*smaller dt.*implicit-euler"):
        for _ in range(10):
            system.step(100.0)


def test_the_memory_budget_is_checked_before_allocating():
    import frustum

    system = ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=1e12, lifetime=1.0)
    with frustum.budget(bytes="1G"), pytest.raises(SimulationError, match=r"over the memory budget"):
        system.step(1.0)


def test_no_particle_ends_a_step_inside_a_mesh_collider():
    import trimesh

    from frustum.geometry.primitives import box, icosphere
    from frustum.simulation import MeshCollider

    solid = icosphere(0.8, 2)
    system = ParticleSystem(
        emitter=DiskEmitter((0, 1.5, 0), radius=0.7, direction=(0, -1, 0), speed=3.0), rate=3000.0, lifetime=2.0,
        forces=[Gravity()], colliders=[MeshCollider(solid, restitution=0.2, friction=0.1)], seed=4,
    )  # fmt: skip
    oracle = trimesh.Trimesh(solid.vertices, solid.faces, process=False)
    bounced = 0
    for _ in range(25):
        system.step(1 / 60)
        # trimesh's own signed distance as the oracle: positive inside; allow round-off of the closest point
        assert trimesh.proximity.signed_distance(oracle, system.positions).max(initial=-1.0) <= 1e-9
        bounced += int((system.velocities[:, 1] > 0).sum())
    assert bounced > 0
    with pytest.raises(SimulationError, match=r"mesh = .* is not a closed Mesh"):
        MeshCollider(Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]))  # an open triangle
    MeshCollider(box())  # a closed box is accepted


def test_the_fused_step_equals_the_numpy_step(monkeypatch):
    import frustum.simulation.particles as particles_module

    def run(minimum: int) -> ParticleSystem:
        monkeypatch.setattr(particles_module, "FUSED_STEP_MINIMUM", minimum)
        system = ParticleSystem(
            emitter=PointEmitter((0, 0.5, 0), spread=1.2, speed=4.0, speed_variance=1.0), rate=20000.0, lifetime=0.4,
            forces=[Gravity(), Drag(0.3), Wind((1.0, 0.0, -0.5), 0.2)], seed=8,
            colliders=[PlaneCollider((0, 0, 0), (0, 1, 0), 0.6, 0.1), PlaneCollider((1, 0, 0), (-1, 0.2, 0), 1.0)],
        )  # fmt: skip
        system.emit(3000)
        for _ in range(30):
            system.step(1 / 50)
        return system

    fused, plain = run(0), run(10**12)
    assert fused.count == plain.count
    # same formulas in another order of floating-point operations: equal to round-off
    np.testing.assert_allclose(fused.positions, plain.positions, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(fused.velocities, plain.velocities, rtol=1e-12, atol=1e-12)
    assert fused.positions[:, 1].min() >= -1e-12


def test_the_fused_step_names_the_step_of_a_blow_up(monkeypatch):
    import frustum.simulation.particles as particles_module

    monkeypatch.setattr(particles_module, "FUSED_STEP_MINIMUM", 0)
    system = ParticleSystem(emitter=PointEmitter((0, 0, 0)), rate=0.0, lifetime=100.0,
                            forces=[Gravity((0, 1e307, 0))], seed=0)  # fmt: skip
    system.emit(4)
    with pytest.raises(SimulationError, match=r"after step \d+"):
        for _ in range(10):
            system.step(100.0)
