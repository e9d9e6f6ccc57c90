"""`python3 -m flexcontact info` prints the stack flexcontact runs on; `demos` lists demos;
`sweep CONFIG.toml` runs a sweep of dam-impact scenarios (docs/dam.md, "Sweeps"); `dam
prepare CONFIG.toml` saves a factored dam and `dam what-if MODEL --log-speed-m-s 3 ...`
answers one scenario from it (docs/dam.md, "A dam model file")."""
import argparse
import json
from pathlib import Path

from .info import describe


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m flexcontact", description=__doc__)
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("info", help="versions, MUMPS, the BLAS in use")
    sub.add_parser("demos", help="list the demos and how to run them")
    from .sweep.cli import add_parser as add_sweep
    add_sweep(sub)
    from .dam.cli import add_parser as add_dam
    add_dam(sub)
    args = ap.parse_args(argv)
    if args.cmd == "dam":
        from .dam.cli import main as dam
        raise SystemExit(dam(args))
    if args.cmd == "sweep":
        from .sweep.cli import main as sweep
        raise SystemExit(sweep(args))
    if args.cmd == "info":
        print(json.dumps(describe(), indent=2))
    elif args.cmd == "demos":
        root = Path(__file__).resolve().parents[3] / "demos"
        if not root.is_dir():
            # A pip-installed package carries the library only; demos are scripts of the
            # source repository.
            raise SystemExit("the demos are scripts of the flexcontact source repository "
                             "(its demos/ folder); this installed package has none")
        for d in sorted(root.glob("*.py")):
            doc = next((l[4:].strip() for l in d.read_text().splitlines()
                        if l.startswith("# # ")), "")
            print(f"/usr/bin/python3 demos/{d.name:24s} {doc}")


if __name__ == "__main__":
    main()
