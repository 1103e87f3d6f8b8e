"""The posterior of the identified parameters by adaptive importance sampling on the exact model
(:mod:`~fracid.inverse.sampling.posterior`), its result and its Gaussian mixtures.

May import :mod:`fracid.inverse.core`, :mod:`fracid.inverse.likelihood` and :mod:`fracid.inverse.methods`; never
the studies.
"""
