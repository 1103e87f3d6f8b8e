"""Studies built on an inverse method's stages and records: the identification study with its checks and
verdict, twins, uniqueness, stability, model comparisons, size effect. They read a method through its
registry and protocols (:class:`~fracid.inverse.methods.registry.StudyMethod`) and its results by the kinds of
their stage records, never by a method's or a stage's name.

The top floor of :mod:`fracid.inverse`: may import every other sub-package of it.
"""
