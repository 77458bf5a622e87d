"""Test set-up: facadecli first, so that its BLAS settings come before numpy is loaded."""

import facadecli  # noqa: F401
