"""``adapt --validate``'s verdict says over how many seeds its means are taken: with few
seeds one unlucky seed of a chaotic run can decide a loss, and a reader of the warning needs
the count to judge it."""

from __future__ import annotations

from sweepfiles import two_context_sweep

from amsa_phys.cli.main import main


def test_the_verdict_names_the_seed_count(tmp_path, capsys) -> None:
    # a lying sweep (Kv 0.8 best with healthy motors): the rules lose on held-out sequences
    path, sweep = two_context_sweep(
        tmp_path,
        {("healthy", 0.2): 0.5, ("healthy", 0.8): 0.3, ("worn", 0.2): 0.5, ("worn", 0.8): 0.6},
    )
    argv = ["adapt", str(sweep), "--scenario", str(path), "-o", str(tmp_path / "r.yaml")]
    argv += ["--validate", "--margin", "inf", "--sequences", "2", "--seeds", "3"]
    code = main([*argv, "--duration", "240"])
    err = capsys.readouterr().err
    assert code == 1
    assert "(by more than 2 % in the mean over 3 seeds)" in err
