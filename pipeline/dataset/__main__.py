"""Export runs as a LeRobot v3.0 dataset (Parquet + metadata + a dataset card), one episode per run.

    python -m pipeline.dataset ur5-ik-fsm/singular-paths              -> data/datasets/ur5-ik-fsm/singular-paths/
    python -m pipeline.dataset ur5-ik-fsm/singular-paths ur5-ik-fsm/random-paths --out data/datasets/ur5-both
    python -m pipeline.dataset --each ur5-ik-fsm/singular-paths ur5-ik-fsm/random-paths   -> a dataset each
    python -m pipeline.dataset --runs data/runs/gripper-force-control/force-error-surface --out /tmp/surface
    python -m pipeline.dataset ur5-ik-fsm/singular-paths --fps 100 --license cc0-1.0

Bad input is refused in one line (exit 2), nothing written; the folder is replaced whole when complete.
"""

from __future__ import annotations

import argparse
import difflib
import sys
import time
from pathlib import Path


def parse(argv: list[str]) -> argparse.Namespace:
    from pipeline.dataset.export import DEFAULT_FPS, DEFAULT_LICENSE, MAX_FPS

    parser = argparse.ArgumentParser(prog="python -m pipeline.dataset", description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog="\n\n".join(__doc__.split("\n\n")[1:]))
    parser.add_argument("experiments", nargs="*", metavar="SLUG/NAME", help="experiments whose runs to export")
    parser.add_argument("--runs", type=Path, action="append", default=[], metavar="DIR",
                        help="a directory of run files (a sweep, episodes); repeatable")
    parser.add_argument("--out", type=Path, help="dataset folder (default data_dir/datasets/<slug>/<name>)")
    parser.add_argument("--each", action="store_true",
                        help="one dataset per experiment, each in its default folder (one process for many)")
    parser.add_argument("--data-dir", type=Path, default=Path("data"), help="where runs are read (default data)")
    parser.add_argument("--fps", type=int, help=f"frames per second (default: the log rate, at most {DEFAULT_FPS})")
    parser.add_argument("--license", default=DEFAULT_LICENSE,
                        help=f"licence id of the card (default {DEFAULT_LICENSE})")
    parser.add_argument("--workers", type=int, default=0, help="processes (default one per core)")
    args = parser.parse_args(argv)
    if not args.experiments and not args.runs:
        parser.error("name an experiment (SLUG/NAME) or a --runs directory")
    if args.each and (args.runs or args.out):
        parser.error("--each exports experiments to their own folders: give no --runs or --out")
    if args.fps is not None and not 1 <= args.fps <= MAX_FPS:
        parser.error(f"--fps={args.fps} must be between 1 and {MAX_FPS}")
    if not 0 <= args.workers <= 64:
        parser.error(f"--workers={args.workers} must be between 0 (one per core) and 64")
    return args


def main(argv: list[str]) -> int:
    args = parse(argv)
    from pipeline.core import interrupts
    from pipeline.core.experiment import available_experiments
    from pipeline.dataset.export import ExportError, Source, experiment_source, export

    known = available_experiments()
    for experiment in args.experiments:
        if experiment not in known:
            hint = difflib.get_close_matches(experiment, known, n=1)
            print(f"error: unknown experiment '{experiment}'" + (f" (did you mean '{hint[0]}'?)" if hint else ""),
                  file=sys.stderr)
            return 2
    sources = [experiment_source(e, args.data_dir) for e in args.experiments] + [Source(d) for d in args.runs]
    for source in sources:
        if not source.runs.is_dir():
            hint = f": run it first, python -m pipeline experiment={source.experiment}" if source.experiment else ""
            print(f"error: no runs at {source.runs}{hint}", file=sys.stderr)
            return 2
    if args.each:
        jobs = [([source], args.data_dir / "datasets" / e) for source, e in zip(sources, args.experiments, strict=True)]
    elif args.out is None and (len(args.experiments) != 1 or args.runs):
        print("error: several sources make one dataset: say where with --out DIR (or --each)", file=sys.stderr)
        return 2
    else:
        jobs = [(sources, args.out or args.data_dir / "datasets" / args.experiments[0])]
    interrupts.install()
    start = time.perf_counter()
    try:
        written = [path for group, out in jobs for path in export(group, out, args.fps, args.license, args.workers)]
    except ExportError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as err:
        print("interrupted: nothing was written", file=sys.stderr)
        return interrupts.exit_code(err)
    for path in written:
        print(f"wrote {path}", file=sys.stderr)
    print(f"exported in {time.perf_counter() - start:.2f} s", file=sys.stderr)
    from pipeline.core import stages

    stages.record(args.data_dir, "export", ",".join(sorted({e.split("/")[0] for e in args.experiments}))
                  or ",".join(str(d) for d in args.runs))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
