"""Operating a fleet of graspsim servers behind a load balancer that routes by scene (docs/scaling.md).

A scene lives on one replica, found by a consistent hash of its id. When replicas are added (or removed), about
1/n of the scenes hash to a new home; until they are moved their calls answer NOT_FOUND. rebalance() moves each
such scene by archive: exported from the replica that holds it, imported through the balancer (which routes the
import to the scene's new home), then deleted from the old replica. Run it once after the balancer has the new
replica list:

    python -m graspsim.fleet rebalance --balancer HOST:PORT --replicas HOST:PORT,HOST:PORT,...
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

import graspsim


@dataclass
class Rebalance:
    """What rebalance() did: scenes kept where they were, moved (id, from replica address), and failures."""
    kept: List[str] = field(default_factory=list)
    moved: List[Tuple[str, str]] = field(default_factory=list)
    failed: List[Tuple[str, str, str]] = field(default_factory=list)  # (scene id, replica, "CODE: message")


def rebalance(balancer: str, replicas: Sequence[str], *, token: Optional[str] = None,
              call_timeout: float = 600.0, dry_run: bool = False) -> Rebalance:
    """Moves every scene whose home (by the balancer's routing) is no longer the replica that holds it.

    balancer: the load balancer's gRPC address; replicas: every replica's own address (reached directly).
    A scene is moved only after its copy exists at its new home; the old copy is deleted last, so a failure
    leaves the scene where it was (reported in .failed). dry_run: only find the scenes that would move.
    """
    result = Rebalance()
    with graspsim.connect(balancer, token=token, call_timeout=call_timeout, fleet=True) as routed:
        for address in replicas:
            with graspsim.connect(address, token=token, call_timeout=call_timeout) as holder:
                for summary in holder.list_scenes():
                    try:
                        routed.get_scene(summary.id)
                        result.kept.append(summary.id)
                        continue
                    except graspsim.NotFound:
                        pass  # the balancer routes this scene to a replica that does not hold it: move it there
                    if dry_run:
                        result.moved.append((summary.id, address))
                        continue
                    try:
                        routed.import_scene(holder.export_scene(summary.id), scene_id=summary.id)  # routed by it
                        holder.delete_scene(summary.id)
                        result.moved.append((summary.id, address))
                    except graspsim.GraspsimError as err:
                        result.failed.append((summary.id, address, str(err)))
    return result


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m graspsim.fleet", description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    move = commands.add_parser("rebalance", help="move the scenes whose home changed to their new replica")
    move.add_argument("--balancer", required=True, help="the load balancer's gRPC address, host:port")
    move.add_argument("--replicas", required=True, help="every replica's own gRPC address, comma-separated")
    move.add_argument("--token", help="a bearer token (scripter or admin) when the servers check tokens")
    move.add_argument("--dry-run", action="store_true", help="only list the scenes that would move")
    args = parser.parse_args(argv)
    result = rebalance(args.balancer, [r for r in args.replicas.split(",") if r], token=args.token,
                       dry_run=args.dry_run)
    for scene_id, source in result.moved:
        print(f"{'would move' if args.dry_run else 'moved'} {scene_id} (was on {source})")
    for scene_id, source, why in result.failed:
        print(f"FAILED {scene_id} on {source}: {why}", file=sys.stderr)
    print(f"{len(result.kept)} kept, {len(result.moved)} {'to move' if args.dry_run else 'moved'}, "
          f"{len(result.failed)} failed")
    return 1 if result.failed else 0


if __name__ == "__main__":
    sys.exit(main())
