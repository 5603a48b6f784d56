"""``to_xml_string`` writes exactly what escaping every attribute value would write.

The serializer writes attribute values unescaped and checks all of them at once
afterwards; these tests compare it with a plain reference on trees whose values need
escaping (in one element or several) and on trees whose values do not.
"""

from __future__ import annotations

import random
import xml.etree.ElementTree as ET

import defusedxml.ElementTree as SafeET

from robotwright.generators.xmlfmt import XML_HEADER, to_xml_string

_ESC = {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "\n": "&#10;", "\r": "&#13;"}
_ESC["\t"] = "&#09;"


def _reference(root: ET.Element) -> str:
    """Escape every value, element by element (the definition)."""
    out = [XML_HEADER]

    def text_of(t: str) -> str:
        return t.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")

    def write(el: ET.Element, indent: str) -> None:
        attrs = "".join(
            f' {k}="{"".join(_ESC.get(c, c) for c in v)}"' for k, v in el.attrib.items()
        )
        text = el.text if el.text is not None and el.text.strip() else None
        if len(el) == 0 and text is None:
            out.append(f"{indent}<{el.tag}{attrs} />\n")
            return
        if len(el) == 0:
            out.append(f"{indent}<{el.tag}{attrs}>{text_of(text or '')}</{el.tag}>\n")
            return
        out.append(f"{indent}<{el.tag}{attrs}>\n")
        if text is not None:
            out.append(f"{indent}  {text_of(text)}\n")
        for child in el:
            if isinstance(child.tag, str):
                write(child, indent + "  ")
        out.append(f"{indent}</{el.tag}>\n")

    write(root, "")
    return "".join(out)


def _random_tree(rng: random.Random, special: float) -> ET.Element:
    plain = ["0 0 1", "link_1", "1.5", "a-b/c.stl", "", " ", "x y"]
    odd = ['a"b', "a&b", "<x>", "l1\nl2", "t\tt", "r\rr", '""', "&amp;"]

    def value() -> str:
        return rng.choice(odd) if rng.random() < special else rng.choice(plain)

    def element(depth: int) -> ET.Element:
        el = ET.Element(rng.choice(["body", "geom", "joint", "site"]))
        for k in rng.sample(["name", "pos", "quat", "file", "rgba", "type"], rng.randint(0, 4)):
            el.set(k, value())
        if rng.random() < 0.1:
            el.text = rng.choice(["text & more", "  ", "a<b"])
        if depth < 3:
            for _ in range(rng.randint(0, 3)):
                el.append(element(depth + 1))
        return el

    root = ET.Element("mujoco", {"model": value()})
    for _ in range(rng.randint(1, 4)):
        root.append(element(0))
    return root


def test_serializer_matches_escaping_every_value() -> None:
    rng = random.Random(2)
    escaped = 0
    for i in range(600):
        root = _random_tree(rng, special=[0.0, 0.02, 0.3][i % 3])
        text = to_xml_string(root)
        assert text == _reference(root)
        escaped += "&quot;" in text or "&amp;" in text or "&#10;" in text
        # and the document reads back with the same attribute values
        back = SafeET.fromstring(text.encode())
        assert [dict(e.attrib) for e in back.iter()] == [dict(e.attrib) for e in root.iter()]
    assert escaped > 100


def test_serializer_escapes_a_single_odd_value_among_many() -> None:
    root = ET.Element("mujoco")
    for i in range(200):
        ET.SubElement(root, "geom", {"name": f"g{i}", "pos": "0 0 0"})
    root[137].set("name", 'say "hi" & <bye>')
    text = to_xml_string(root)
    assert 'name="say &quot;hi&quot; &amp; &lt;bye&gt;"' in text
    assert text == _reference(root)
