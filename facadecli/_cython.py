"""What a module written for Cython asks of ``cython`` when it runs interpreted and Cython
is not installed (it is a build requirement, never a runtime one): only whether it is
compiled. Compiled, Cython reads ``import cython`` itself and this module is not used."""

compiled = False
