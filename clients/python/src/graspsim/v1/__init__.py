"""Generated gRPC stubs of the graspsim v1 API (proto/graspsim/v1), written here at build time by setup.py."""
