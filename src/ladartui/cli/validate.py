"""``ladartui validate SCENARIO``: load and check a scenario, then describe it."""

from __future__ import annotations


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "validate",
        help="check a scenario file and summarise it",
        description="Load a scenario, check every field against its limits and that its scene "
        "and target model files exist, then print a summary (sensor, scans, path length, "
        "flight time, outputs). A mistake is reported on one line with exit status 2.",
    )
    parser.add_argument("scenario", metavar="SCENARIO", help="scenario file (.toml)")
    parser.set_defaults(handler=run)
    return parser


def run(args) -> int:
    from ladartui.scenario import load_scenario

    scenario = load_scenario(args.scenario)
    print(scenario.summary())
    return 0
