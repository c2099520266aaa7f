"""Deprecated alias of graspsim.testing.partial_view, where the test rigs now live; removed in the next release."""
import sys
import warnings

from graspsim.testing import partial_view as _moved

warnings.warn(f"{__name__} is deprecated: import graspsim.testing.partial_view", DeprecationWarning, stacklevel=2)
# The old name is the new module itself, so that patching one patches the other.
sys.modules[__name__] = _moved
