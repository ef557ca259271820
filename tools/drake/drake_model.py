"""The walker as a Drake MultibodyPlant (hydroelastic contact, discrete SAP/Similar solver).

Bodies, joints and contact geometry follow `src/sim/model.rs`:
* left leg = floating base (explicit QuaternionFloatingJoint to the world), body frame
  origin at the hip point, axes aligned with the world when standing upright;
* right leg on a RevoluteJoint about the left leg's +y axis, q = rotation of the right
  leg relative to the left;
* each leg's foot: a compliant hydroelastic Ellipsoid (modulus E, mesh resolution hint
  `resolution_hint_over_l`·L) centred at the design's foot centre in the leg frame;
* ground: rigid hydroelastic HalfSpace z ≤ 0 on the world body; a slope is modelled as in
  the project by tilting gravity (the ground stays z = 0). With the `soft_ground` effect:
  a compliant hydroelastic Box slab instead (top face z = 0, thickness 2·R_z, modulus E_g;
  Drake refuses a compliant HalfSpace against a compliant foot), see `ground_slab`.
The hip actuator and the hardstop are one LeafSystem (`HipController`) writing the
plant's applied generalized force input: explicit, i.e. held over each time step at its
value from the state at the start of the step (Drake's discrete plant samples its inputs
at the start of the step). Drake's joint limits are NOT used.
Effects: `hip_viscous_damping` is the RevoluteJoint's own damping (implicit in Drake's
discrete solver); `hip_coulomb_friction` is added by `HipController` (explicit, like the
hardstop); `friction_coefficient` sets μ on both geometries; `soft_ground` as above.
"""

from __future__ import annotations

import logging
import math

import numpy as np
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddContactMaterial,
    AddRigidHydroelasticProperties,
    Box,
    CollisionFilterDeclaration,
    Ellipsoid,
    GeometrySet,
    HalfSpace,
    ProximityProperties,
)
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CoulombFriction,
    MultibodyPlantConfig,
)
from pydrake.multibody.tree import (
    QuaternionFloatingJoint,
    RevoluteJoint,
    RotationalInertia,
    SpatialInertia,
)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from design import Model, controller_torque, hardstop_torque, hip_coulomb_torque

# Lateral half-size of the soft-ground slab, in leg lengths (the walks travel < 30 L).
GROUND_SLAB_HALF_SIZE_OVER_L = 200.0


def ground_slab(model: Model):
    """(thickness, lateral half-size) [m] of the compliant ground slab for `soft_ground`.

    Drake gives a compliant Box the pressure field p = E_g·d/d_max (d = distance to the
    box's boundary, d_max = half its smallest dimension), so near the middle of the top face
    it is the field of a compliant half space with slab thickness h = d_max: gradient E_g/h.
    Two compliant fields meet where their pressures are equal, and to first order in the
    penetration the pressure of the pair is δ·g_foot·g_ground/(g_foot + g_ground). The foot's
    field p = E(1 − r) has gradient E/R_z at its lowest point, so h = R_z gives
    δ·(E/R_z)·(E_g/R_z)/((E + E_g)/R_z) = δ·E_eff/R_z with E_eff = E·E_g/(E + E_g): the foot
    pressed into a rigid floor with the project's series modulus. Thickness 2·R_z."""
    rz = max(leg.foot_semi_axes_m[2] for leg in model.legs)
    return 2.0 * rz, GROUND_SLAB_HALF_SIZE_OVER_L * model.leg_length_m


class _QuietHalfSpaceWarning(logging.Filter):
    """Drops Drake's (irrelevant here) note that rigid half spaces do not take part in
    deformable contact; every other message passes."""

    def filter(self, record):
        return "half spaces are not currently supported for deformable" not in record.getMessage()


logging.getLogger("drake").addFilter(_QuietHalfSpaceWarning())


class HipController(LeafSystem):
    """Hip actuator (servo / bang-bang / passive) plus hardstop, as a generalized force."""

    def __init__(self, plant, model: Model, hip_joint, actuated: bool = True,
                 servo_in_plant: bool = False):
        super().__init__()
        self._ctl = model.controller if actuated else {"kind": "passive"}
        # With the servo inside the plant (SAP PD actuator) only the hardstop is applied here.
        self._servo_in_plant = servo_in_plant
        self._hs = model.hardstop
        self._coulomb = list(model.hip_coulomb)
        self._nv = plant.num_velocities()
        self._iq = hip_joint.position_start()
        self._iv = plant.num_positions() + hip_joint.velocity_start()
        self._jv = hip_joint.velocity_start()
        self.DeclareVectorInputPort("plant_state", plant.num_multibody_states())
        self.DeclareVectorOutputPort("generalized_force", self._nv, self._calc)
        # (t, q, q̇, actuator torque, hardstop torque) of the last evaluation.
        self.last = (math.nan, math.nan, math.nan, 0.0, 0.0)
        self.last_coulomb = 0.0

    def _calc(self, context, output):
        x = self.get_input_port(0).Eval(context)
        t = context.get_time()
        q, qd = float(x[self._iq]), float(x[self._iv])
        tau = 0.0 if self._servo_in_plant else controller_torque(self._ctl, t, q, qd)
        hs = hardstop_torque(self._hs, q, qd)
        fr = hip_coulomb_torque(self._coulomb, qd) if self._coulomb else 0.0
        out = np.zeros(self._nv)
        out[self._jv] = tau + hs + fr
        output.SetFromVector(out)
        self.last = (t, q, qd, tau, hs)
        self.last_coulomb = fr


class ServoReference(LeafSystem):
    """Desired hip state [q_d, q̇_d] = [A sin ωt, Aω cos ωt] for the plant's PD actuator,
    evaluated at the END of the step (t + dt): SAP's PD constraint acts on the end-of-step
    state (q_{k+1}, v_{k+1}), so a target sampled at the start of the step would make the
    servo lag by one step (0.5 deg at 1.4 Hz, dt = 1 ms). With the lead the servo is a
    consistent backward-Euler discretisation of the continuous law."""

    def __init__(self, ctl: dict, lead_s: float):
        super().__init__()
        self._a = ctl["amplitude_rad"]
        self._w = 2.0 * math.pi * ctl["frequency_hz"]
        self._lead = lead_s
        self.DeclareVectorOutputPort("desired_state", 2, self._calc)

    def _calc(self, context, output):
        t = context.get_time() + self._lead
        output.SetFromVector([self._a * math.sin(self._w * t),
                              self._a * self._w * math.cos(self._w * t)])


class DrakeWalker:
    """A built diagram, its simulator, and accessors in the project's conventions."""

    def __init__(self, model: Model, resolution_hint_over_l: float = 0.06,
                 actuated: bool = True, time_step_s: float | None = None,
                 sap_near_rigid_threshold: float = 1.0, servo: str = "auto",
                 approximation: str | None = None):
        """servo: 'sap_pd' (Drake's PD-controlled joint actuator, implicit in the discrete
        solver, effort limit = torque limit), 'explicit' (the servo law in the LeafSystem,
        torque held over the step), or 'auto' (default: 'sap_pd' for an actuated
        servo_sine design, else the LeafSystem)."""
        self.model = model
        if servo == "auto":
            servo = "sap_pd" if (actuated and model.controller["kind"] == "servo_sine") else "explicit"
        if servo not in ("explicit", "sap_pd"):
            raise ValueError(servo)
        if servo == "sap_pd" and (not actuated or model.controller["kind"] != "servo_sine"):
            raise ValueError("servo='sap_pd' needs an actuated servo_sine design")
        self.servo = servo
        L = model.leg_length_m
        self.resolution_hint_m = resolution_hint_over_l * L
        self.time_step_s = time_step_s if time_step_s is not None else model.time_step_s
        if approximation is None:
            # Kelvin-Voigt (relaxation time) -> SAP; Hunt-Crossley -> 'similar'.
            approximation = "sap" if model.dissipation_kind == "kelvin_voigt" else "similar"
        self.approximation = approximation
        config = MultibodyPlantConfig(
            time_step=self.time_step_s,
            discrete_contact_approximation=approximation,
            contact_model="hydroelastic",
            contact_surface_representation="polygon",
            # Used by 'similar' (Hunt-Crossley) only: regularisation speed of friction,
            # f(s) = s/sqrt(1+s²) with s = |v_t|/v_s, as in the project's law. SAP ignores it.
            stiction_tolerance=model.stiction_speed_mps,
            sap_near_rigid_threshold=sap_near_rigid_threshold,
            use_sampled_output_ports=True,
            adjacent_bodies_collision_filters=True,
        )
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlant(config, builder)
        self.plant, self.scene_graph = plant, scene_graph

        bodies = []
        for name, leg in zip(("left_leg", "right_leg"), model.legs):
            inertia = SpatialInertia.MakeFromCentralInertia(
                leg.mass_kg, leg.com_m,
                RotationalInertia(*[float(v) for v in leg.inertia_diag_kgm2]))
            bodies.append(plant.AddRigidBody(name, inertia))
        self.left, self.right = bodies
        self.floating = plant.AddJoint(QuaternionFloatingJoint(
            "left_floating", plant.world_frame(), self.left.body_frame()))
        # hip_viscous_damping: Drake's joint damping τ = −c·q̇ (implicit in the discrete
        # solver: it enters the linearised dynamics matrix as dt·c).
        self.hip = plant.AddJoint(RevoluteJoint(
            "hip", self.left.body_frame(), self.right.body_frame(), [0.0, 1.0, 0.0],
            float(model.hip_damping_nms_per_rad)))

        mu = model.friction_mu
        friction = CoulombFriction(mu, mu)
        self.foot_ids = []
        if model.ground_contact:
            for body, leg in zip(bodies, model.legs):
                props = ProximityProperties()
                AddCompliantHydroelasticProperties(
                    self.resolution_hint_m, model.modulus_pa, props)
                hc = model.hunt_crossley_s_per_m if model.hunt_crossley_s_per_m is not None else 0.0
                AddContactMaterial(dissipation=hc, friction=friction, properties=props)
                if model.relaxation_time_s is not None:
                    props.AddProperty("material", "relaxation_time", model.relaxation_time_s)
                gid = plant.RegisterCollisionGeometry(
                    body, RigidTransform(leg.foot_center_m),
                    Ellipsoid(*[float(a) for a in leg.foot_semi_axes_m]),
                    body.name() + "_foot", props)
                self.foot_ids.append(gid)
            ground = ProximityProperties()
            if model.ground_modulus_pa is None:
                AddRigidHydroelasticProperties(ground)
                shape, X_ground = HalfSpace(), RigidTransform()
                # Its Hunt-Crossley d is not used (the compliant foot's d is, for a rigid
                # partner).
                ground_d = 0.0
            else:
                # soft_ground: compliant slab, top face at z = 0 (see ground_slab). The
                # resolution hint is ignored for a Box (Drake's medial-axis box mesh, on which
                # the linear field is exact).
                thick, half = ground_slab(model)
                AddCompliantHydroelasticProperties(thick, model.ground_modulus_pa, ground)
                shape = Box(2.0 * half, 2.0 * half, thick)
                X_ground = RigidTransform([0.0, 0.0, -0.5 * thick])
                # Drake weights two compliant geometries' Hunt-Crossley d by their
                # stiffnesses; the same d on both keeps the design's d (the project's
                # soft_ground changes the modulus only).
                ground_d = model.hunt_crossley_s_per_m if model.hunt_crossley_s_per_m is not None else 0.0
            # Drake adds the two geometries' relaxation times; the ground adds 0.
            AddContactMaterial(dissipation=ground_d, friction=friction, properties=ground)
            ground.AddProperty("material", "relaxation_time", 0.0)
            self.ground_id = plant.RegisterCollisionGeometry(
                plant.world_body(), X_ground, shape, "ground", ground)
        self.actuator = None
        if servo == "sap_pd":
            from pydrake.multibody.tree import PdControllerGains
            ctl = model.controller
            self.actuator = plant.AddJointActuator("hip_servo", self.hip, ctl["torque_limit_nm"])
            self.actuator.set_controller_gains(
                PdControllerGains(p=ctl["kp_nm_per_rad"], d=ctl["kd_nms_per_rad"]))
        g = model.gravity_mps2
        plant.mutable_gravity_field().set_gravity_vector(np.asarray(g, dtype=float))
        plant.Finalize()
        if len(self.foot_ids) == 2:
            # The feet overlap at the mid-plane; never let them touch each other (also
            # filtered as adjacent bodies; stated explicitly).
            scene_graph.collision_filter_manager().Apply(
                CollisionFilterDeclaration().ExcludeWithin(GeometrySet(self.foot_ids)))

        self.controller = builder.AddSystem(
            HipController(plant, model, self.hip, actuated=actuated,
                          servo_in_plant=(servo == "sap_pd")))
        builder.Connect(plant.get_state_output_port(), self.controller.get_input_port(0))
        builder.Connect(self.controller.get_output_port(0),
                        plant.get_applied_generalized_force_input_port())
        if servo == "sap_pd":
            ref = builder.AddSystem(ServoReference(model.controller, self.time_step_s))
            builder.Connect(ref.get_output_port(0), plant.get_desired_state_input_port(
                self.left.model_instance()))
            builder.ExportInput(plant.get_actuation_input_port(), "feedforward")
        self.diagram = builder.Build()
        self.simulator = Simulator(self.diagram)
        self.context = self.simulator.get_mutable_context()
        self.plant_context = plant.GetMyMutableContextFromRoot(self.context)
        self.step_index = 0
        self._foot_index = {gid: k for k, gid in enumerate(self.foot_ids)}
        self._q_quat = self.floating.position_start()      # qw qx qy qz x y z
        self._v_float = self.floating.velocity_start()     # wx wy wz vx vy vz (world)
        self._iq = self.hip.position_start()
        self._iv = self.hip.velocity_start()

    # --- state -------------------------------------------------------------------------
    def set_state(self, hip_position_m, R_left, hip_angle_rad=0.0,
                  hip_velocity_mps=(0, 0, 0), omega_left_body=(0, 0, 0), hip_rate=0.0):
        """Sets the state in the project's coordinates (ω of the left leg in ITS frame)."""
        p = self.plant
        ctx = self.plant_context
        X = RigidTransform(RotationMatrix(np.asarray(R_left, dtype=float)),
                           np.asarray(hip_position_m, dtype=float))
        self.floating.SetPose(ctx, X)
        w_world = np.asarray(R_left, dtype=float) @ np.asarray(omega_left_body, dtype=float)
        self.floating.set_angular_velocity(ctx, w_world)
        self.floating.set_translational_velocity(ctx, np.asarray(hip_velocity_mps, dtype=float))
        self.hip.set_angle(ctx, hip_angle_rad)
        self.hip.set_angular_rate(ctx, hip_rate)
        self.context.SetTime(0.0)
        self.step_index = 0
        if self.actuator is not None:
            self.diagram.get_input_port(0).FixValue(self.context, [0.0])
        self.simulator.Initialize()

    def time(self) -> float:
        return self.context.get_time()

    def positions(self):
        return self.plant.GetPositions(self.plant_context)

    def velocities(self):
        return self.plant.GetVelocities(self.plant_context)

    def pose(self):
        """(hip position world, R_left (3x3), q, q̇, ω_left world, v_hip world)."""
        qv = self.positions()
        vv = self.velocities()
        i = self._q_quat
        w, x, y, z = qv[i:i + 4]
        n = math.sqrt(w * w + x * x + y * y + z * z)
        w, x, y, z = w / n, x / n, y / n, z / n
        R = np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ])
        p = qv[i + 4:i + 7].copy()
        j = self._v_float
        return p, R, float(qv[self._iq]), float(vv[self._iv]), vv[j:j + 3].copy(), vv[j + 3:j + 6].copy()

    def hip_rate(self) -> float:
        return float(self.velocities()[self._iv])

    # --- stepping ----------------------------------------------------------------------
    def step(self):
        """Advances one time step; returns (actuator torque applied during the step,
        hardstop torque)."""
        self.step_index += 1
        self.simulator.AdvanceTo(self.step_index * self.time_step_s)
        t, _, _, tau, hs = self.controller.last
        if self.actuator is not None:
            # Sampled port: the actuation the solver applied during the last step.
            u = self.plant.get_net_actuation_output_port().Eval(self.plant_context)
            tau = float(u[self.actuator.input_start()])
        return tau, hs, t

    def contact(self):
        """Per-foot contact of the last step (sampled output port: the contact results the
        solver computed from the state at the start of the last step):
        (feet in contact, [|Fz left|, |Fz right|], [polygons left, right], [centroid x,y,z]...)."""
        if not self.foot_ids:
            return 0, [0.0, 0.0], [0, 0], [None, None], [np.zeros(3), np.zeros(3)]
        cr = self.plant.get_contact_results_output_port().Eval(self.plant_context)
        fz = [0.0, 0.0]
        faces = [0, 0]
        inc = [False, False]
        area = [0.0, 0.0]
        force = [np.zeros(3), np.zeros(3)]
        for i in range(cr.num_hydroelastic_contacts()):
            info = cr.hydroelastic_contact_info(i)
            s = info.contact_surface()
            for gid, sign in ((s.id_M(), 1.0), (s.id_N(), -1.0)):
                k = self._foot_index.get(gid)
                if k is None:
                    continue
                # F_Ac_W is the force on body A (geometry M); on N it is the opposite.
                f = sign * info.F_Ac_W().translational()
                fz[k] += abs(float(f[2]))
                force[k] = force[k] + f
                faces[k] += s.num_faces()
                area[k] += s.total_area()
                inc[k] = True
        return sum(inc), fz, faces, area, force
