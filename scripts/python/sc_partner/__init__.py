"""Partner SDK of the safe-capture partition (docs/PARTNER.md).

Write a nominal controller as a subclass of :class:`NominalController` that
implements ``step(state) -> command``; run it in the partition with
``MyController.main()`` (the launcher starts it with ``SC_RUN_ID`` and ``--config``),
or offline on a recorded ``telemetry.csv`` with :mod:`sc_partner.harness`.
A navigation (estimator) is a subclass of :class:`Navigation` that implements
``estimate(measurement) -> estimate``, run the same way (offline on a partition run's
``recording.mcap``).

Modules: :mod:`sc_partner.icd` (the messages and constants, standard library only),
:mod:`sc_partner.bus` (iceoryx2 services with the partition's settings, the
handshake), :mod:`sc_partner.controller` (the base class and the process loop),
:mod:`sc_partner.navigation` (the navigation's base class),
:mod:`sc_partner.process` (the loop every partner process runs),
:mod:`sc_partner.harness` (offline runs), :mod:`sc_partner.config` (partition config
and scenario), :mod:`sc_partner.examples` (the worked example).

The names below are imported on first use, so that ``python -m sc_partner.icd`` needs
neither numpy nor iceoryx2.
"""

__version__ = "0.1.0"

_LAZY = {
    "NominalController": "controller",
    "State": "controller",
    "run_partition": "controller",
    "Navigation": "navigation",
    "Measurement": "navigation",
    "Estimate": "navigation",
    "states_from_telemetry": "harness",
    "run_offline": "harness",
}

__all__ = sorted(_LAZY)


def __getattr__(name):
    if name in _LAZY:
        import importlib

        module = importlib.import_module(f".{_LAZY[name]}", __name__)
        return getattr(module, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
