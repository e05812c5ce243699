"""The terminal UI (the only package that imports textual)."""


def run_app(scenario_path=None, graphics_mode: str | None = None) -> int:
    """Open the app on ``scenario_path`` (default scenario when None); returns an exit code.

    How the views reach the terminal is chosen first (``graphics_mode`` forces it), while
    the terminal's answers can still be read (tui/graphics.py).
    """
    import os

    from ladartui.tui.graphics import detect, has_truecolor

    graphics, problems = detect(graphics_mode)
    if graphics.image and not has_truecolor(os.environ):
        # terminals that show images show 24-bit colour (and kitty's image cells need it)
        os.environ["COLORTERM"] = "truecolor"

    from ladartui.tui.app import LadarApp

    app = LadarApp(scenario_path, graphics=graphics, graphics_problems=problems)
    app.run()
    return app.return_code or 0  # 1 when the app ended on an error (its traceback shown)
