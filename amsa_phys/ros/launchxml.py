"""The launch file of one scenario (``launch/NAME.launch``, roslaunch XML).

Names reach it through :mod:`.quote` only: attribute values through ``xml_attr`` (which also
refuses ``$(``, since roslaunch evaluates substitutions inside attributes), comments through
``xml_comment`` (XML comments cannot hold ``--``) and the ``<rosparam>`` list, which
roslaunch's rosparam loader reads as YAML, as double-quoted YAML scalars.
"""

from __future__ import annotations

from .._version import __version__
from ..model.rosnames import NAMESPACE_BASE, P_PIPELINE, P_RULES
from . import boundary, names
from .cppnode import hz, plugin
from .graph import RosGraph
from .quote import Code, fill, yaml_scalar

#: The launch arguments (constant text: no user name in them).
_ARGS = """\
  <arg name="mode" default="@@{mode:xml_attr}" doc="lockstep: reproduces amsa-phys run byte for\
 byte; free: every node on its own timer (not reproducible)"/>
  <arg name="out" default="" doc="run directory (default: runs/NAME-STAMP in the current\
 directory)"/>
  <arg name="force" default="false" doc="replace an out directory amsa-phys made"/>
  <arg name="bag" default="" doc="record every Data topic to this .bag file (an absolute path)"/>
  <arg name="speed" default="1.0" doc="free mode: simulated seconds per wall second"/>
  <arg name="duration" default="@@{duration:xml_attr}" doc="simulated seconds to run (empty: the\
 scenario's; export --duration sets it)"/>
  <arg name="plots" default="true" doc="draw distance.png and trajectory.png"/>
  <arg name="timeout" default="60" doc="seconds to wait for a node before giving up"/>
  <arg name="waves" default="true" doc="lockstep: ask together the nodes of an instant whose\
 inputs are fixed (false: one at a time, for comparison)"/>
  <arg name="sim" default="true" doc="false: the controller side alone, in free mode, for a real\
 robot whose drivers publish the standard topics (see README.md)"/>
  <arg name="boundary" default="$(eval arg('mode') != 'lockstep' or not arg('sim'))"\
 doc="the robot boundary's standard messages (default: in free mode and with sim:=false; in\
 lockstep only when asked, boundary:=true, since it costs the replica time)"/>"""

_HEAD = """\
  <param name="/use_sim_time" value="true"/>
  <group ns="@@{namespace:xml_attr}">
    <param name="scenario" value="$(find @@{pkg:xml_attr})/config/@@{fname:xml_attr}.yaml"/>
    <param if="$(arg sim)" name="mode" value="$(arg mode)"/>
    <param unless="$(arg sim)" name="mode" value="free"/>
    <param name="sim" type="bool" value="$(arg sim)"/>
    <param name="boundary" type="bool" value="$(arg boundary)"/>
    <param name="bag" type="bool" value="$(eval arg('bag') != '')"/>
    <param name="timeout" type="double" value="$(arg timeout)"/>
    <param name="seed" type="str" value="@@{seed:xml_attr}"/>
    <rosparam param="local">@@{local:xml_text}</rosparam>
@@{container:code}  </group>
  <rosparam command="load" file="$(find @@{pkg:xml_attr})/config/@@{fname:xml_attr}_params.yaml"/>

  <!-- the physics (@@{local_names:xml_comment}) and /clock; writes the run directory -->
  <node if="$(arg sim)" pkg="@@{pkg:xml_attr}" type="@@{simulator:xml_attr}.py"\
 name="@@{simulator:xml_attr}" required="true" output="screen">
    <param name="out" value="$(arg out)"/>
    <param name="force" type="bool" value="$(arg force)"/>
    <param name="speed" type="double" value="$(arg speed)"/>
    <param name="duration" type="str" value="$(arg duration)"/>
    <param name="plots" type="bool" value="$(arg plots)"/>
    <param name="waves" type="bool" value="$(arg waves)"/>
  </node>
  <node if="$(arg sim)" pkg="@@{pkg:xml_attr}" type="@@{scenario:xml_attr}.py"\
 name="@@{scenario:xml_attr}" required="true" output="screen"/>
  <!-- the robot boundary: standard messages (sim:=false: from the robot's drivers in, and
       /clock from the wall clock) -->
  <node if="$(arg boundary)" pkg="@@{pkg:xml_attr}" type="@@{boundary:xml_attr}.py"\
 name="@@{boundary:xml_attr}"\
 output="screen">
    <param name="speed" type="double" value="$(arg speed)"/>
  </node>
"""


def _container(cpp: list[str]) -> Code:
    """``rosnames.P_CONTAINER``: the Leaves in the C++ container when it runs (cpp and
    cpp_container), else none; every node counts its subscribers (processes) by it."""
    if not cpp:
        return Code("")
    on = "$(eval arg('cpp') and arg('cpp_container'))"
    leaves = Code("[" + ", ".join(yaml_scalar(p) for p in cpp) + "]")
    return fill(
        '    <rosparam if="@@{on:code}" param="container">@@{leaves:xml_text}</rosparam>\n'
        '    <rosparam unless="@@{on:code}" param="container">[]</rosparam>\n',
        on=Code(on),
        leaves=leaves,
    )


def _pipeline(adapt: bool) -> str:
    """The ``pipeline`` argument and ``rosnames.P_PIPELINE``: lockstep asks the C++ container for
    many instants at once, checking each answer against the in-process template
    (``runtime/pipeline.py``), when every remote Leaf is in the container, no bag records the
    topics, the boundary node does not run (its Python publishers could not keep up with a
    simulator that outruns them: their queues drop messages) and (with ``adapt:`` rules) the
    simulator fires the rules. Constant text."""
    when = (
        "arg('pipeline') and arg('mode') == 'lockstep' and arg('sim') and arg('cpp')"
        " and arg('cpp_container') and arg('bag') == '' and not arg('boundary')"
        + (" and arg('rules') != 'node'" if adapt else "")
    )
    return (
        '  <arg name="pipeline" default="true" doc="lockstep with every Leaf in the C++'
        " container: ask it for many instants at once, each answer checked bit for bit"
        " against the Leaf&apos;s in-process template (false: wait for every instant&apos;s"
        ' answers, the nodes&apos; values driving the run)"/>\n'
        + fill(
            '  <param name="@@{name:xml_attr}" type="bool" value="$(eval @@{when:code})"/>',
            name=P_PIPELINE,
            when=Code(when),
        )
    )


_LEAF = "  <!-- @@{path:xml_comment}: @@{tname:xml_comment}, @@{hz:xml_comment} Hz -->"
_COMMON = 'pkg="@@{pkg:xml_attr}" name="@@{base:xml_attr}"@@{ns:code} required="true"'


def launch_xml(
    graph: RosGraph,
    pkg: str,
    fname: str,
    mode: str,
    cpp: list[str],
    source: str,
    adapt: bool = False,
    seed: int = 0,
    duration: str = "",
) -> str:
    """The launch file of the scenario whose config files are ``config/FNAME*.yaml``
    (``adapt``: it has ``adapt:`` rules, run by the adapt node when ``sim:=false``; ``seed``:
    the scenario's, ``rosnames.P_SEED``, read by the C++ sensors for their random streams;
    ``duration``: the ``duration:=`` default, ``export --duration``'s cut or "")."""
    data_topics = " ".join(graph.data_topics())
    local = [p for p in graph.world.leaves if p in graph.local]
    lines = [
        '<?xml version="1.0"?>',
        fill(
            "<!-- Generated by amsa-phys @@{version:xml_comment} from @@{source:xml_comment}:"
            " scenario @@{fname:xml_comment} of @@{pkg:xml_comment}."
            " roslaunch @@{pkg:xml_comment} @@{fname:xml_comment}.launch [arg:=value ...] -->",
            version=__version__,
            source=source,
            fname=fname,
            pkg=pkg,
        ),
        "<launch>",
        fill(_ARGS, mode=mode, duration=duration),
    ]
    if cpp:
        lines.append(
            '  <arg name="cpp" default="true" doc="run the Leaves with a C++ body as their'
            ' roscpp node (false: their Python twin)"/>'
        )
        lines.append(
            '  <arg name="cpp_container" default="true" doc="with cpp: every C++ Leaf in one'
            " process (amsa_leaves, a nodelet manager); false: one process per Leaf (nodelet"
            ' standalone)"/>'
        )
    lines.append(
        fill(
            _HEAD,
            pkg=pkg,
            fname=fname,
            local=Code("[" + ", ".join(yaml_scalar(p) for p in local) + "]"),
            local_names=", ".join(local) or "no Leaf",
            simulator=names.SIMULATOR,
            scenario=names.SCENARIO,
            boundary=boundary.NODE,
            seed=str(seed),
            container=_container(cpp),
            namespace=NAMESPACE_BASE,
        )
    )
    if adapt:
        lines.append(
            fill(
                '  <arg name="rules" default="sim" doc="lockstep: sim fires the adapt: rules'
                " inside the simulator; node asks the amsa_adapt node (the one sim:=false"
                ' runs), for comparison"/>\n'
                '  <param name="@@{rules:xml_attr}" value="$(arg rules)"/>\n'
                "  <!-- adapt: rules (sim:=false, or rules:=node in lockstep; else they fire"
                " inside the simulator) -->\n"
                "  <node if=\"$(eval not arg('sim') or (arg('rules') == 'node' and"
                ' arg(\'mode\') == \'lockstep\'))" pkg="@@{pkg:xml_attr}" type="amsa_adapt.py"'
                ' name="amsa_adapt" required="true" output="screen"/>',
                pkg=pkg,
                rules=P_RULES,
            )
        )
    if cpp and set(cpp) == set(graph.remote):
        lines.append(_pipeline(adapt))
    if cpp:
        lines.append(
            fill(
                "  <!-- the C++ Leaves: their wiring, and their container (every C++ Leaf in"
                " one process) -->\n"
                '  <rosparam if="$(arg cpp)" command="load"'
                ' file="$(find @@{pkg:xml_attr})/config/@@{container:xml_attr}.yaml"/>\n'
                "  <node if=\"$(eval arg('cpp') and arg('cpp_container'))\""
                ' pkg="@@{pkg:xml_attr}" type="@@{container:xml_attr}"'
                ' name="@@{container:xml_attr}" required="true" output="screen"/>',
                pkg=pkg,
                container=names.CONTAINER,
            )
        )
    side = boundary.plan(graph).controller
    for path in graph.remote:
        leaf = graph.leaf(path)
        parent, _, base = path.rpartition(".")
        lines.append(fill(_LEAF, path=path, tname=leaf.template.name(), hz=hz(leaf.freq)))
        ns = fill(' ns="@@{ns:xml_attr}"', ns=names.ns(parent)) if parent else Code("")
        common = fill(_COMMON, pkg=pkg, base=base, ns=ns)
        script = names.script(path)
        node = '  <node @@{when:code}@@{c:code} type="@@{t:xml_attr}"/>'
        # sim:=false runs the controller side only (boundary.py); the rest is the simulator's
        sim = "True" if path in side else "arg('sim')"
        if path in cpp:
            # cpp_container:=false: the Leaf's nodelet alone in a process of its own
            alone = Code(f"if=\"$(eval {sim} and arg('cpp') and not arg('cpp_container'))\" ")
            cpp_off = Code(f"if=\"$(eval {sim} and not arg('cpp'))\" ")
            lines.append(
                fill(
                    '  <node @@{when:code}pkg="nodelet" type="nodelet"'
                    ' args="standalone @@{plugin:xml_attr}" name="@@{base:xml_attr}"@@{ns:code}'
                    ' required="true"/>',
                    when=alone,
                    plugin=plugin(pkg, leaf.template.name()),
                    base=base,
                    ns=ns,
                )
            )
            lines.append(fill(node, when=cpp_off, c=common, t=f"{script}.py"))
        else:
            when = Code("" if path in side else 'if="$(arg sim)" ')
            lines.append(fill(node, when=when, c=common, t=f"{script}.py"))
    lines += [
        "",
        "  <!-- bag:=FILE.bag records every Data topic (connected before the run starts; it"
        " never drops a message: a recorder behind slows the run; required: a bag it cannot"
        " write ends the launch at once, saying why) -->",
        fill(
            "  <node if=\"$(eval arg('bag') != '')\" pkg=\"@@{pkg:xml_attr}\""
            ' type="@@{bag:xml_attr}.py" name="@@{bag:xml_attr}" required="true"'
            ' output="screen"',
            pkg=pkg,
            bag=names.BAG,
        ),
        fill('        args="-O $(arg bag) @@{topics:xml_attr}"/>', topics=data_topics),
        "</launch>",
    ]
    return "\n".join(lines) + "\n"
