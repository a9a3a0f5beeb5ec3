"""``adapt --validate``'s verdict says over how many seeds its means are taken: with few
seeds one unlucky seed of a chaotic run can decide a loss, and a reader of the warning needs
the count to judge it."""

from __future__ import annotations

from sweepfiles import two_context_sweep

from amsa_phys.cli.main import main


def _validate_lying_sweep(tmp_path) -> list[str]:  # type: ignore[no-untyped-def]
    """``adapt --validate`` of a lying sweep (Kv 0.8 best with healthy motors): the rules
    lose on held-out sequences."""
    path, sweep = two_context_sweep(
        tmp_path,
        {("healthy", 0.2): 0.5, ("healthy", 0.8): 0.3, ("worn", 0.2): 0.5, ("worn", 0.8): 0.6},
    )
    argv = ["adapt", str(sweep), "--scenario", str(path), "-o", str(tmp_path / "r.yaml")]
    return [*argv, "--validate", "--margin", "inf"]


def test_the_verdict_names_the_seed_count(tmp_path, capsys) -> None:
    argv = _validate_lying_sweep(tmp_path)
    argv += ["--sequences", "2", "--seeds", "3"]
    code = main([*argv, "--duration", "240"])
    err = capsys.readouterr().err
    assert code == 1
    assert "(by more than 2 % in the mean over 3 seeds)" in err


def test_one_sequence_and_one_seed_are_said_in_the_singular(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    argv = _validate_lying_sweep(tmp_path)
    argv += ["--sequences", "1", "--seeds", "1"]
    main([*argv, "--duration", "240"])
    said = capsys.readouterr()
    assert "\nvalidating on 1 held-out sequence x 1 seed (" in said.out
    assert said.out.endswith("on 1 held-out sequence, in the mean over 1 seed\n") or (
        "1 of 1 held-out sequence (by more than 2 % in the mean over 1 seed)" in said.err
    )


def test_sequences_too_short_for_a_switch_are_said(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """60 s sequences hold one context each: the verdict scores no switch, and says so."""
    argv = _validate_lying_sweep(tmp_path)
    argv += ["--sequences", "1", "--seeds", "1"]
    main([*argv, "--duration", "60"])
    err = capsys.readouterr().err
    assert (
        "warning: held-out sequences of 60 s hold one context each (a context lasts at least "
        "60 s): no switch between contexts is scored; give --duration 120 or more"
    ) in err
    main([*argv, "--duration", "240", "--force"])
    assert "hold one context each" not in capsys.readouterr().err
