"""Suite-wide set-up: tests never write into the user's home folder."""

import os
import tempfile

# The default scenario and benchmark scenes live under LADARTUI_HOME; point it
# at a throw-away folder before any test imports ladartui.
os.environ.setdefault("LADARTUI_HOME", tempfile.mkdtemp(prefix="ladartui-test-home-"))
