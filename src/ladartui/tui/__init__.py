"""The terminal UI (the only package that imports textual)."""


def run_app(scenario_path=None) -> int:
    """Open the app on ``scenario_path`` (default scenario when None); returns an exit code."""
    from ladartui.tui.app import LadarApp

    LadarApp(scenario_path).run()
    return 0
