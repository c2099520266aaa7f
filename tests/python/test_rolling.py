"""Rolling without slipping against the closed form (issue 21): a sphere and a cylinder on a 20° incline, and a
sphere whose friction is too low to roll, which slides. The incline is the gravity vector tilted by θ over a
static floor, which is the same problem. Closed forms: rolling a = g sin θ / (1 + I / (m r²)), so 5/7 g sin θ for
a solid sphere and 2/3 g sin θ for a solid cylinder, when μ ≥ (I / (I + m r²)) tan θ; otherwise the body slides
with a = g (sin θ − μ cos θ) at its centre. Each acceleration is a least-squares fit of x(t) over 1 s of motion."""
import numpy as np
import pytest

THETA, G = np.radians(20), 9.81


def acceleration(client, scene_id, shape, mu, dt=1e-3, seconds=1.0):
    client.set_simulation_params(scene_id, time_step=dt, gravity=(G * np.sin(THETA), 0, -G * np.cos(THETA)))
    client.add_object(scene_id, "floor", box=[20, 1, 0.1], pose=[0, 0, -0.05, 1, 0, 0, 0], is_static=True,
                      friction=[mu, mu])
    r = 0.05
    if shape == "sphere":
        client.add_object(scene_id, "body", sphere=r, mass=1.0, pose=[0, 0, r, 1, 0, 0, 0], friction=[mu, mu])
    else:  # axis along y: it rolls along x
        q = [np.cos(np.pi / 4), np.sin(np.pi / 4), 0, 0]
        client.add_object(scene_id, "body", cylinder=[r, 0.1], mass=1.0, pose=[0, 0, r, *q], friction=[mu, mu])
    client.step_simulation(scene_id, duration=0.1)  # settled on the floor, moving
    times, xs = [], []
    steps = int(round(0.02 / dt))
    for _ in range(int(seconds / 0.02)):
        times.append(client.step_simulation(scene_id, steps=steps).time)
        xs.append(client.get_body_poses(scene_id, ["body"])["body"].position[0])
    return 2 * np.polyfit(times, xs, 2)[0]


@pytest.mark.parametrize("shape, factor", [("sphere", 5 / 7), ("cylinder", 2 / 3)])
@pytest.mark.parametrize("dt", [2e-3, 1e-3, 2.5e-4])
def test_rolling_without_slipping_matches_the_closed_form(client, scene_id, shape, factor, dt):
    expected = factor * G * np.sin(THETA)
    assert acceleration(client, scene_id, shape, mu=1.0, dt=dt) == pytest.approx(expected, rel=5e-3)


def test_a_sphere_with_too_little_friction_slides(client, scene_id):
    mu = 0.05  # below (2/7) tan 20° = 0.104: it cannot roll
    expected = G * (np.sin(THETA) - mu * np.cos(THETA))
    assert acceleration(client, scene_id, "sphere", mu=mu) == pytest.approx(expected, rel=1e-2)
