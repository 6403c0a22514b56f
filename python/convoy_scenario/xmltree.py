"""A small XML tree that remembers where each element came from (file and line), so that
every error about a scenario can name the file, the element and its line.

Read with xml.parsers.expat (standard library): namespaces are not processed, comments and
processing instructions are dropped, character data is kept only to reject it where
OpenSCENARIO has none (every value of the format is an attribute).
"""

import os
import xml.parsers.expat


class ScenarioError(Exception):
    """A scenario outside the supported subset, or wrong: the message names the file, the
    line and the element (``cut_in.xosc:42: <UserDefinedAction> is not supported ...``)."""


class Node:
    """One XML element: tag, attributes (in document order), children, file and line."""

    __slots__ = ("tag", "attrib", "children", "path", "line", "text")

    def __init__(self, tag, attrib, path, line):
        self.tag = tag
        self.attrib = attrib
        self.children = []
        self.path = path
        self.line = line
        self.text = ""

    def where(self):
        """``file.xosc:LINE`` (the file's base name)."""
        return "%s:%d" % (os.path.basename(self.path), self.line)

    def error(self, message):
        """A ScenarioError about this element: ``file:line: <Tag> message``."""
        return ScenarioError("%s: <%s> %s" % (self.where(), self.tag, message))

    def find(self, tag):
        """The first child named tag, or None."""
        for c in self.children:
            if c.tag == tag:
                return c
        return None

    def findall(self, tag):
        return [c for c in self.children if c.tag == tag]

    def need(self, tag):
        """The child named tag; a ScenarioError when there is none."""
        c = self.find(tag)
        if c is None:
            raise self.error("needs a <%s>" % tag)
        return c

    def only_child(self, choices):
        """The one child of this element, which must be one of choices (the schema check has
        already refused the others)."""
        kids = [c for c in self.children if c.tag in choices]
        if len(kids) != 1:
            raise self.error("needs exactly one of <%s>" % ">, <".join(choices))
        return kids[0]


def parse_file(path):
    """The root Node of the XML file at path; ScenarioError (file:line) if it cannot be read
    or is not well-formed XML."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise ScenarioError("%s: cannot read: %s" % (path, e.strerror or e)) from None
    return parse_bytes(data, path)


def parse_bytes(data, path):
    parser = xml.parsers.expat.ParserCreate()
    stack = []
    root = []

    def start(tag, attrs):
        node = Node(tag, dict(attrs), path, parser.CurrentLineNumber)
        if stack:
            stack[-1].children.append(node)
        else:
            root.append(node)
        stack.append(node)

    def end(tag):
        stack.pop()

    def chars(text):
        if stack:
            stack[-1].text += text

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = chars
    parser.ordered_attributes = False
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as e:
        raise ScenarioError("%s:%d: not well-formed XML: %s" % (
            os.path.basename(path), e.lineno, xml.parsers.expat.ErrorString(e.code))) from None
    return root[0]
