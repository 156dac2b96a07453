"""Runs the pytest suite of the evfs module for ctest (python/CMakeLists.txt).

Exits 77, which ctest reports as skipped, when pytest or NumPy is not installed (Debian:
python3-pytest, python3-numpy); otherwise with pytest's own status.
"""
import importlib.util
import sys

SKIPPED = 77

if __name__ == "__main__":
    missing = [m for m in ("pytest", "numpy") if importlib.util.find_spec(m) is None]
    if missing:
        print("skipped: " + ", ".join(missing) + " not installed for " + sys.executable +
              " (Debian: python3-pytest python3-numpy)")
        sys.exit(SKIPPED)
    import pytest
    sys.exit(pytest.main(["-q", "-p", "no:cacheprovider"] + sys.argv[1:]))
