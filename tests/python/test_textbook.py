"""The physics against textbook closed forms (issue 21), through the server: every case of tests/physics/textbook.py
within 1 % of its closed form at dt = 1 ms, its error not rising as dt falls (over 2, 1, 0.5, 0.25 and 0.1 ms,
within the measurement floor textbook.ERROR_FLOOR), and the conservative cases keeping their energy within 0.5 %
over their run (10 s) with velocity Verlet, the integrator documented for smooth motion."""
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "physics"))
import textbook  # noqa: E402
from graspsim_engine import GraspsimEngine  # noqa: E402


@pytest.mark.parametrize("case", textbook.CASES, ids=[c.name for c in textbook.CASES])
def test_case_is_within_1pct_at_1ms_and_converges(client, case):
    outcomes = textbook.run_case(case, lambda: GraspsimEngine(client))
    errors = [outcomes[dt].error for dt in textbook.TIME_STEPS]
    table = ", ".join(f"{dt * 1e3:g} ms: {e:.3e}" for dt, e in zip(textbook.TIME_STEPS, errors))
    assert outcomes[1e-3].error <= 0.01, f"{case.name}: {table}"
    assert textbook.converging(errors), f"{case.name} does not converge: {table}"
    if case.conservative and not math.isnan(outcomes[1e-3].energy_drift):
        assert outcomes[1e-3].energy_drift <= 5e-3, f"{case.name}: energy drift {outcomes[1e-3].energy_drift:.2e}"

