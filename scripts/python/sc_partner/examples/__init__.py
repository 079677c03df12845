"""Worked examples: a nominal controller (:class:`sc_partner.NominalController`) and a navigation (:class:`sc_partner.Navigation`)."""
