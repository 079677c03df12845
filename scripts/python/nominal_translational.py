#!/usr/bin/env python3
"""The worked example (``sc_partner/examples/nominal_translational.py``) run from a
checkout, without installing the package: config/partition_python.toml starts it as

    [roles.nominal_translational]
    exec = "../scripts/.venv/bin/python"
    args = ["../scripts/python/nominal_translational.py"]

With the package installed (``pip install ./scripts/python``) the same controller is the
command ``sc-partner-nominal-translational`` (docs/PARTNER.md).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sc_partner.examples.nominal_translational import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
