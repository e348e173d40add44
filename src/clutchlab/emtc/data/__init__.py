"""Bundled synthetic data of the EMTC subsystem (see ``generate_forc.py``)."""
