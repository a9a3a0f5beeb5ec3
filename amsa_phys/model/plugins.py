"""Templates installed as plugins: the ``amsa_phys.templates`` entry-point group.

Python's convention for plugins is entry points: a package declares in its
``pyproject.toml``::

    [project.entry-points."amsa_phys.templates"]
    PidFollower = "my_rovers.templates:PidFollower"

and once it is installed (``pip install my-rovers``) a world can name ``template:
PidFollower`` (or ``my_rovers.templates:PidFollower``) without any PYTHONPATH. Only the
installed packages' metadata is read here, never their code: the module is imported when
a world names the template, exactly as an explicit ``module:Class`` is (the same trust
rule: code runs only where a file names it, from a package the user installed).

A plugin cannot shadow a built-in name (the built-in wins and ``amsa-phys templates`` says
the plugin's name is taken), and a name two installed packages both register is refused
as ambiguous, naming both (use ``module:Class`` then).
"""

from __future__ import annotations

from dataclasses import dataclass

#: The entry-point group plugin packages register their templates in.
GROUP = "amsa_phys.templates"


@dataclass(frozen=True)
class Plugin:
    """One registered template: its short name, ``module:Class`` and the distribution."""

    name: str
    target: str
    distribution: str


def installed() -> dict[str, list[Plugin]]:
    """Every registered template name and who registers it (sorted, deterministic).

    Reads the installed distributions' metadata (``importlib.metadata``): a few
    milliseconds, done only when a template name is neither built in nor ``module:Class``.
    """
    from importlib.metadata import entry_points

    found: dict[str, list[Plugin]] = {}
    for ep in entry_points(group=GROUP):
        dist = ep.dist.name if ep.dist is not None else "an unnamed distribution"
        found.setdefault(ep.name, []).append(Plugin(ep.name, ep.value, dist))
    return {name: sorted(found[name], key=lambda p: p.distribution) for name in sorted(found)}


def target_of(name: str, plugins: dict[str, list[Plugin]] | None = None) -> str | None:
    """The ``module:Class`` a short plugin name stands for (None if none registers it).

    Raises ``LookupError`` (the caller's TemplateNotFound) if several packages do.
    """
    found = (installed() if plugins is None else plugins).get(name, [])
    if len(found) > 1:
        who = ", ".join(f"{p.distribution} ({p.target})" for p in found)
        raise LookupError(
            f"template name {name!r} is registered by several installed packages: {who}; "
            "name one as module:Class"
        )
    return found[0].target if found else None
