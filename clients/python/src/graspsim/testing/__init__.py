"""Rigs for tests and local experiments (never imported by the client itself): fleet.Fleet runs several
graspsim-server replicas behind HAProxy on loopback."""
