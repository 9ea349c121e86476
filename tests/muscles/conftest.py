"""tests/muscles: OpenSim, when it is imported, writes no ``opensim.log`` beside the model it
loads (its file sink writes into the package's data folder, which the sdist would then carry)."""

import pytest


@pytest.fixture(autouse=True, scope="session")
def _no_opensim_log():
    try:
        import opensim
    except ImportError:
        yield
        return
    opensim.Logger.removeFileSink()
    yield
