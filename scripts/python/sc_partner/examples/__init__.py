"""Worked examples of partner controllers on :class:`sc_partner.NominalController`."""
