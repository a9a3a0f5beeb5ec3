"""Robust tuning: controller parameters good over a whole context distribution.

``amsa-phys tune`` minimises a tail measure (the worst case, or CVaR) of a metric over
contexts and seeds; its answer is the fixed choice that ``amsa-phys adapt`` rules must beat
(``adapt --validate`` measures them against it on held-out context sequences).
"""
