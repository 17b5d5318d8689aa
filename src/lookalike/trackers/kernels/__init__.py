"""Compiled (numba) paths behind the parts they speed up, each with a switch; the numpy code is the reference
and the tests check that both give the same results."""
