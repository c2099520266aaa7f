"""A scene on the graspsim server as a textbook engine (scene_spec.Engine): built and stepped through the Python client,
with the server's defaults except the time step (and Runge–Kutta 4 for smooth scenes). engine= picks the
server's physics engine (SimulationParams.engine: "graspsim", "mujoco"), the same API on each."""
from __future__ import annotations

import numpy as np

import graspsim
from scene_spec import BodyState, Scene


class GraspsimEngine:
    def __init__(self, client: graspsim.Client, engine: str = "graspsim", **params):
        self.client = client
        self.name = engine
        self.params = dict(params, engine=engine)  # SimulationParams fields beside the time step, by name
        self.scene_id = ""

    def load(self, scene: Scene, dt: float) -> None:
        c = self.client
        self.scene_id = c.create_scene("textbook").id
        params = dict(time_step=dt, gravity=scene.gravity)
        if scene.smooth:
            params["integrator"] = "runge_kutta_4"
        self.params = {**params, **self.params}
        c.set_simulation_params(self.scene_id, **self.params)
        for robot in scene.robots:
            c.add_robot(self.scene_id, robot.name, urdf=robot.urdf, base_pose=list(robot.base_pose))
            if robot.joint_positions:
                c.set_joint_positions(self.scene_id,
                                      {f"{robot.name}/{j}": q for j, q in robot.joint_positions.items()})
        for body in scene.bodies:
            shape = {"box": dict(box=list(body.size)), "sphere": dict(sphere=body.size[0]),
                     "cylinder": dict(cylinder=list(body.size))}[body.shape]
            mass = {} if body.static else dict(mass=body.mass, inertia=np.diag(body.inertia_diagonal()).tolist())
            c.add_object(self.scene_id, body.name, **shape, **mass, pose=list(body.pose), is_static=body.static,
                         friction=list(body.friction))
            if body.velocity is not None:
                c.set_body_velocities(self.scene_id, {body.name: body.velocity})

    def set_gravity(self, gravity) -> None:
        self.params["gravity"] = tuple(gravity)
        self.client.set_simulation_params(self.scene_id, **self.params)

    def push(self, robot: str, joint: str, force: float) -> None:
        # The joint's default DC motor in voltage mode: standing still, force = ratio η k_t V / R, 5 N per volt
        # (R 1 Ω, k_t 0.05 N m/A, ratio 100, η 1: world/simulation_params.h).
        self.client.set_actuator(self.scene_id, f"{robot}/{joint}", "voltage", force / 5.0)

    def step(self, steps: int) -> None:
        self.client.step_simulation(self.scene_id, steps=steps)

    def body(self, name: str) -> BodyState:
        pose = self.client.get_body_poses(self.scene_id, [name])[name]
        velocity = self.client.get_body_velocities(self.scene_id, [name])[name]
        return BodyState(pose.position, pose.orientation, velocity.linear, velocity.angular)

    def joint(self, robot: str, joint: str):
        joint_id = f"{robot}/{joint}"
        return (self.client.get_joint_positions(self.scene_id, [joint_id])[joint_id],
                self.client.get_joint_velocities(self.scene_id, [joint_id])[joint_id])

    def close(self) -> None:
        if self.scene_id:
            self.client.delete_scene(self.scene_id)
            self.scene_id = ""
