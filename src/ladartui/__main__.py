from ladartui.cli import entry

entry()
