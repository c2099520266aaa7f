"""Rigs for tests and local experiments (never imported by the client itself): fleet.Fleet runs several
graspsim-server replicas behind HAProxy on loopback; gateway_rig.GatewayRig runs device emulators and a
graspsim-gateway; partial_view renders the depth image a camera would give of a mesh."""
from graspsim.testing import fleet, gateway_rig, partial_view
from graspsim.testing.fleet import Fleet
from graspsim.testing.gateway_rig import GatewayRig

__all__ = ["Fleet", "GatewayRig", "fleet", "gateway_rig", "partial_view"]
