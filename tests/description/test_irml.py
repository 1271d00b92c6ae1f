import math
import re

import numpy as np
import pytest

from joulepath.description import (
    irml_string,
    parse_irml,
    preset_description,
    read_irml,
    write_irml,
)
from joulepath.errors import InvalidRobotDescription

MINIMAL_JOINT = """
  <joint id="{id}">
    <type>R</type><xi>1</xi>
    <kinematics><q>q{id}</q><d>0.1</d><r>0.2</r><a>-pi/2</a></kinematics>
    <dynamics><link-mass>1.5</link-mass>
      <center><x>0</x><y>0</y><z>0.05</z></center>
      <inertia><xx>0.01</xx><xy>0</xy><xz>0</xz><yx>0</yx><yy>0.01</yy><yz>0</yz>
               <zx>0</zx><zy>0</zy><zz>0.01</zz></inertia></dynamics>
  </joint>"""


def robot_xml(*joint_xml: str) -> str:
    return "<robot><name>T</name>" + "".join(joint_xml) + "</robot>"


def good(n: int = 2) -> str:
    return robot_xml(*(MINIMAL_JOINT.format(id=i + 1) for i in range(n)))


def test_parse_irml_minimal():
    desc = parse_irml(good(), source="mini.irml")
    assert desc.name == "T"
    assert [j.id for j in desc.joints] == [1, 2]
    j = desc.joints[0]
    assert (j.d, j.r, j.alpha, j.offset, j.sign) == (0.1, 0.2, -math.pi / 2, 0.0, 1.0)
    assert j.inertial.mass == 1.5


def test_read_irml_appendix_c_loads(appendix_c_path):
    desc = read_irml(appendix_c_path)
    assert desc.name == "IRB 120" and desc.manufacturer == "ABB"
    assert len(desc.joints) == 6
    assert desc.info_value("ambient/maximal-humidity") == "95"
    assert desc.info_value("loads/maximal-loads/tz") == "155"
    assert sum(j.inertial.mass for j in desc.joints) == pytest.approx(11.394, abs=1e-3)


@pytest.mark.parametrize("which", ["appendix", "irb120"])
def test_irml_round_trip_is_identical(which, appendix_c_path, tmp_path):
    desc = read_irml(appendix_c_path) if which == "appendix" else preset_description("irb120")
    out = write_irml(desc, tmp_path / "copy.irml")
    again = read_irml(out)
    assert again == desc
    assert irml_string(again) == irml_string(desc)
    assert not list(tmp_path.glob(".*tmp"))  # no temporary file left behind


def test_irml_string_writes_angles_as_multiples_of_pi():
    text = irml_string(preset_description("irb120"))
    assert "<q>q2 - pi/2</q>" in text and "<q>q6 + pi</q>" in text
    assert "<a>-pi/2</a>" in text


def _break(text: str, old: str, new: str, count: int = 1) -> str:
    assert old in text
    return text.replace(old, new, count)


@pytest.mark.parametrize(
    ("mutate", "pattern"),
    [
        (lambda t: _break(t, "<d>0.1</d>", ""), r"bad\.irml: joint 1 <kinematics>: missing <d>"),
        (
            lambda t: _break(t, "<link-mass>1.5</link-mass>", "<link-mass>heavy</link-mass>"),
            r"bad\.irml: joint 1 <dynamics> <link-mass>: 'heavy'.*write a number",
        ),
        (
            lambda t: _break(t, "<type>R</type>", "<type>X</type>"),
            r"bad\.irml: joint 1 <type>: unknown joint type 'X'; use T .*R .*L",
        ),
        (lambda t: _break(t, 'id="2"', 'id="1"'), r"bad\.irml: joint 1: duplicate joint id"),
        (lambda t: _break(t, "<zz>0.01</zz>", ""), r"joint 1 <dynamics> <inertia>: missing <zz>"),
        (lambda t: _break(t, "<q>q1</q>", "<q>q3</q>"), r"joint 1 <kinematics> <q>: 'q3'"),
        (lambda t: _break(t, "<q>q1</q>", "<q>2*q1</q>"), r"is not ±q1 plus a constant offset"),
        (
            lambda t: _break(t, "<xi>1</xi>", "<xi>0</xi>"),
            r"joint 1 <xi>: xi is 0 but the type is R",
        ),
        (lambda t: _break(t, "<type>R</type>", "<type>L</type>"), r"linear \(prismatic\)"),
        (lambda t: _break(t, '<joint id="1">', "<joint>"), r"<joint>: has no id attribute"),
        (
            lambda t: _break(t, '<joint id="1">', '<joint id="one">'),
            r"joint 'one': id is not an integer",
        ),
        (lambda t: _break(t, "<name>T</name>", ""), r"robot: missing <name>"),
        (lambda t: t[:-10], r"bad\.irml: line \d+, column \d+: not well-formed XML"),
        (lambda t: t.replace("robot>", "robt>"), r"the root element is <robt>"),
        (lambda t: _break(t, "<d>0.1</d>", "<d>0.1</d><d>0.2</d>"), r"<d> appears 2 times"),
        (lambda t: _break(t, "<r>0.2</r>", "<r></r>"), r"joint 1 <kinematics> <r>: is empty"),
    ],
)
def test_parse_irml_malformed_gives_clear_error(mutate, pattern):
    with pytest.raises(InvalidRobotDescription, match=pattern):
        parse_irml(mutate(good()), source="bad.irml")


def test_parse_irml_entity_bomb_is_refused():
    bomb = (
        '<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol">'
        '<!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">'
        '<!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">]>'
        "<robot><name>&lol3;</name></robot>"
    )
    with pytest.raises(InvalidRobotDescription, match=r"bomb\.irml: XML: refused.*entities"):
        parse_irml(bomb, source="bomb.irml")


def test_parse_irml_external_entity_is_refused(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("x")
    xxe = (
        f'<?xml version="1.0"?><!DOCTYPE r [<!ENTITY s SYSTEM "file://{secret}">]>'
        "<robot><name>&s;</name></robot>"
    )
    with pytest.raises(InvalidRobotDescription, match="refused"):
        parse_irml(xxe, source="xxe.irml")


def test_read_irml_missing_file(tmp_path):
    with pytest.raises(InvalidRobotDescription, match=r"nope\.irml: cannot be read"):
        read_irml(tmp_path / "nope.irml")


def test_parse_irml_limits_and_range_sets():
    text = (
        good(1)
        .replace(
            "</joint>",
            "<limits><lower>-pi</lower><upper>pi/2</upper><velocity>4</velocity></limits></joint>",
        )
        .replace(
            "</robot>",
            '<range-set name="cell"><joint id="1"><lower>-1</lower><upper>1</upper></joint>'
            "</range-set></robot>",
        )
    )
    desc = parse_irml(text)
    j = desc.joints[0]
    assert (j.lower, j.upper, j.velocity, j.effort) == (-math.pi, math.pi / 2, 4.0, None)
    assert desc.range_set("cell").lower == (-1.0,)
    with pytest.raises(ValueError, match=r"no range set 'lab'; known: nominal, cell"):
        desc.range_set("lab")


def test_parse_irml_range_set_must_cover_all_joints():
    text = good(2).replace(
        "</robot>",
        '<range-set name="cell"><joint id="1"><lower>-1</lower><upper>1</upper></joint></range-set></robot>',
    )
    with pytest.raises(InvalidRobotDescription, match=r"range-set 'cell': has no range for joint\(s\) \[2\]"):
        parse_irml(text)


def test_preset_irb120_dh_matches_thesis_table_2_1():
    desc = preset_description("irb120")
    assert [j.d for j in desc.joints] == [0.29, 0, 0, 0.302, 0, 0.072]
    assert [j.r for j in desc.joints] == [0, 0.27, 0.07, 0, 0, 0]
    np.testing.assert_allclose([j.alpha for j in desc.joints], np.array([-1, 0, -1, 1, -1, 0]) * math.pi / 2)
    np.testing.assert_allclose(np.degrees([j.offset for j in desc.joints]), [0, -90, 0, 0, 0, 180])
    lab = desc.range_set("lab")
    np.testing.assert_allclose(np.degrees(lab.lower), [-90, -10, -100, -160, -120, -400])
    np.testing.assert_allclose(np.degrees(lab.upper), [90, 45, 40, 160, 120, 400])


def test_irml_error_messages_name_file_joint_and_tag():
    with pytest.raises(InvalidRobotDescription) as info:
        parse_irml(good().replace("<x>0</x>", "<x>zero</x>", 2), source="cell/robot.irml")
    msg = str(info.value)
    assert re.match(r"cell/robot\.irml: joint 1 <dynamics> <center> <x>: 'zero'", msg)


@pytest.mark.parametrize(
    ("mutate", "pattern"),
    [
        (lambda t: _break(t, "<d>0.1</d>", "<d>(-1)**0.5</d>"), r"joint 1 <kinematics> <d>: .*is complex"),
        (lambda t: _break(t, "<q>q1</q>", "<q>q1 + (-2)**0.5</q>"), r"joint 1 <kinematics> <q>: .*complex"),
        (
            lambda t: t.replace("<name>T</name>", "<name>T</name>" + "<a>" * 2000 + "</a>" * 2000),
            r"<a>: general information is nested deeper than 16 levels",
        ),
        (lambda t: ("<?xml version='1.0' encoding='klingon'?>" + t).encode(), r"XML: cannot be decoded"),
        (lambda t: _break(t, 'id="1"', f'id="{"9" * 5000}"'), r"id is not an integer"),
        (lambda t: _break(t, 'id="1"', 'id="1_0"'), r"id is not an integer"),
        (lambda t: t.replace("<name>T</name>", "<name>T</name><reach>nan</reach>"), r"<reach>: 'nan'"),
        (lambda t: t.replace("<name>T</name>", "<name>T</name><reach>1e999</reach>"), r"not a finite"),
    ],
)
def test_parse_irml_hostile_values_give_invalid_robot_description(mutate, pattern):
    with pytest.raises(InvalidRobotDescription, match=pattern):
        parse_irml(mutate(good()), source="bad.irml")


def test_parse_irml_refuses_too_many_joints_and_oversized_text():
    with pytest.raises(InvalidRobotDescription, match="has 65 joints; at most 64"):
        parse_irml(good(65))
    with pytest.raises(InvalidRobotDescription, match="larger than 4 MiB"):
        parse_irml(good().replace("<name>", " " * (5 << 20) + "<name>"))


def test_parse_irml_keeps_shallow_general_information_in_order():
    text = good().replace("<name>T</name>", "<name>T</name><a><b>1</b><c><d>2</d></c></a><e>3</e>")
    assert parse_irml(text).info == (("a/b", "1"), ("a/c/d", "2"), ("e", "3"))


def test_read_irml_refuses_a_folder(tmp_path):
    with pytest.raises(InvalidRobotDescription, match="is a folder"):
        read_irml(tmp_path)
