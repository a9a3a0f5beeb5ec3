"""Requirements as objectives: which number of a run an objective name means, which way is
better (``objective``). The STL itself is in ``amsa_phys.stl``.
"""
