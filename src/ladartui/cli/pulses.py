"""``ladartui pulses``: coverage and false alarms against Geiger-mode pulses per look."""

from __future__ import annotations

from ladartui.errors import FieldError


def add_parser(sub):
    p = sub.add_parser("pulses", help="obscured coverage and false alarms against pulses per look "
                       "(Geiger-mode detection; see docs/detection.md)")
    p.add_argument("scenario", nargs="?", help="scenario TOML (default: the default scenario)")
    p.add_argument("--pulses", default="1,10,100", help="comma-separated pulses per look")
    p.add_argument("--n-ref", type=float, default=5.0,
                   help="mean photoelectrons of a full-footprint return at the reference range")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--backend", default=None)
    p.set_defaults(handler=run)


def run(args) -> int:
    from ladartui.defaults import default_scenario_path
    from ladartui.detection.pulses import GeigerSettings, pulse_study
    from ladartui.scenario import load_scenario

    try:
        pulses = [int(v) for v in args.pulses.split(",")]
    except ValueError:
        raise FieldError("--pulses", args.pulses, "comma-separated whole numbers") from None
    if any(p < 1 or p > 100_000 for p in pulses):
        raise FieldError("--pulses", args.pulses, "pulse counts in 1..100000")
    scenario = load_scenario(args.scenario or default_scenario_path())
    settings = GeigerSettings(n_ref=args.n_ref, seed=args.seed)
    ideal, rows = pulse_study(scenario, pulses, settings, backend=args.backend)
    print(f"ideal model: obscured coverage {ideal:.4f}")
    print(f"{'pulses':>7} {'k':>4} {'coverage':>9} {'declared':>9} {'false':>7} {'P_d(target)':>11}")
    for r in rows:
        print(f"{r.pulses:>7} {r.threshold:>4} {r.obscured_coverage:>9.4f} {r.declared_points:>9} "
              f"{r.false_alarms:>7} {r.target_detection:>11.3f}")
    return 0
