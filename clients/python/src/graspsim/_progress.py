"""The tqdm bars of the long calls (plan_grasps, complete_shape, pick_and_place, run_work_cycle, the graspsim.batch
jobs): on stderr; progress=False on the call, or TQDM_DISABLE=1 in the environment, turns them off."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Dict

if TYPE_CHECKING:
    from tqdm import tqdm


def progress_bar(enabled: bool, total: float, desc: str, unit: str, *, leave: bool = False,
                 initial: float = 0) -> tqdm[Any]:
    """A tqdm bar; a disabled one (every method a no-op) when not `enabled`, so callers never test for it.
    leave=False: a call's bar disappears when the call returns; a batch job keeps its bar as a summary."""
    from tqdm import tqdm  # here, not at the top: `import graspsim` stays fast

    # disable=False given explicitly would override TQDM_DISABLE=1, so it is only ever given as True.
    off: Dict[str, Any] = {} if enabled else {"disable": True}
    return tqdm(total=total, desc=desc, unit=unit, leave=leave, initial=initial, **off)


def advance(bar: tqdm[Any], n: float, status: str = "") -> None:
    """Moves `bar` to n (the server reports positions, not steps) with `status` after it. update() rather than
    setting bar.n redraws at most every tqdm.mininterval: a fast stream does not flood the terminal."""
    if status:
        bar.set_postfix_str(status, refresh=False)
    bar.update(n - bar.n)
