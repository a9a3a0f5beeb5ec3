"""The fastest path speed (m/s) of each (context, Kv) run of ``tests/fixtures/adapt``'s sweep,
as a ``pathSpeed`` requirement's robustness would give it: the cells choose nominal 0.2, worn
0.4, random 0.4 and speed changes 0.1; nominal at 0.4 swings (not chosen). Shared by the
adaptation tests that need the damping rule and the motor fallback's release."""

SPEEDS = {
    ("nominal", "0.1"): 0.2,
    ("nominal", "0.2"): 0.26,
    ("nominal", "0.4"): 1.5,
    ("worn", "0.1"): 0.2,
    ("worn", "0.2"): 0.22,
    ("worn", "0.4"): 0.31,
    ("random", "0.1"): 0.2,
    ("random", "0.2"): 0.2,
    ("random", "0.4"): 0.24,
    ("speed changes", "0.1"): 0.22,
    ("speed changes", "0.2"): 0.9,
    ("speed changes", "0.4"): 1.4,
}
