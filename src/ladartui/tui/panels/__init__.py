"""The sidebar's panels, one per tab: files, sensor, flight, run and results.

Each panel owns its widgets and fields, shows the scenario it is handed
(``show``) and changes the scenario only through the app's ``edit``.
"""

from ladartui.tui.panels.files import FilePanel
from ladartui.tui.panels.flight import FlightPanel
from ladartui.tui.panels.results import ResultsPanel
from ladartui.tui.panels.run import RunPanel
from ladartui.tui.panels.sensor import SensorPanel

__all__ = ["FilePanel", "FlightPanel", "ResultsPanel", "RunPanel", "SensorPanel"]
