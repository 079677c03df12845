#!/usr/bin/env python3
"""The worked navigation example (``sc_partner/examples/navigation.py``) run from a
checkout, without installing the package: a partition config starts it as

    [roles.navigation]
    exec = "../scripts/.venv/bin/python"
    args = ["../scripts/python/navigation.py"]

With the package installed (``pip install ./scripts/python``) the same navigation is the
command ``sc-partner-navigation`` (docs/PARTNER.md).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sc_partner.examples.navigation import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
