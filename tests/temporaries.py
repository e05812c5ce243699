"""Recording the temporaries an output set makes (tests of all-or-nothing writes)."""

import tempfile


def record_temporaries(monkeypatch) -> list[str]:
    """The prefixes of the temporaries made from now on (``tempfile.mkstemp`` with the
    ".tmp" suffix; writability probes use another), filled in as they are made."""
    real, made = tempfile.mkstemp, []

    def recording(*args, **options):
        if options.get("suffix") == ".tmp":
            made.append(options.get("prefix", ""))
        return real(*args, **options)

    monkeypatch.setattr(tempfile, "mkstemp", recording)
    return made
