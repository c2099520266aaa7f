"""Deprecated alias of graspsim.testing.gateway_rig, where the test rigs now live; removed in the next release."""
import sys
import warnings

from graspsim.testing import gateway_rig as _moved

warnings.warn(f"{__name__} is deprecated: import graspsim.testing.gateway_rig", DeprecationWarning, stacklevel=2)
# The old name is the new module itself, so that patching one patches the other.
sys.modules[__name__] = _moved
