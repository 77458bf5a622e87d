"""The layout solver (Ilčík et al. 2015, section 5), one axis at a time:
candidates.py -> alignment.py (per group) -> sizing.py, driven by axis.py."""
