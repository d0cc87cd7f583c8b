"""XML plan files: read into the located tree, write plain data back as XML.

The XML form says exactly what the YAML form says (see ``docs/plan_format.md``).
:func:`read_xml` reads a file into the same located tree that
:mod:`alica.io.yaml_format` produces for the same content, so the one builder
(:mod:`alica.io.build`) gives equal documents for both; :func:`write_xml`
turns the plain data of :func:`alica.io.dump.document_data` into XML. The
schema of the XML form is ``alica/io/schema/plan.xsd``.

Vocabulary
==========

One regular rule maps XML to the tree: **an element is a mapping; its
attributes are keys with text values; a child element is a key too**, read by
the shape the table below gives it. Tags and attributes are the YAML keys
(singular tags for list entries)::

    element          attributes (text)                  children -> key (shape)
    ---------------  ---------------------------------  ---------------------------------------------
    <alica>          version (-> 'alica')               import -> imports (names, or href="...")
                                                        predicate, function -> predicates,
                                                        functions (lists)
                                                        skill -> skills (list)
                                                        task, roleset, behaviour, plan, plantype,
                                                        problem -> tasks ... problems (lists)
    <skill>          name doc                           capability -> capabilities (names),
                                                        parameter -> params (list)
    <parameter> of a <skill>: name type required        default (value), when the attribute cannot
                     default doc                        hold it (see "Skill declarations" below)
    <task>           name description
    <roleset>        name default_priority description  role -> roles (list)
    <role>           name description                   requires -> requires (names)
                                                        priority -> priorities (entries by 'task')
    <behaviour>      name skill frequency description   variable -> variables (list), param -> params
                                                        (entries by 'name'), pre run post (text)
    <plan>           name frequency description         variable -> variables (list), pre run (text),
                                                        utility (one), constraint -> constraints (list),
                                                        signature (one), entrypoint -> entry_points,
                                                        state -> states, synchronisation ->
                                                        synchronisations (lists)
    <utility>        priority_weight similarity_weight  summand -> summands (list)
                     threshold
    <summand>        name weight                        its text -> expression
    <constraint>     name                               variable -> variables (names), formula utility (text)
    <signature>      cost                               parameter -> parameters (list),
                                                        precondition effect (text)
    <entrypoint>     name task state min max
                     success_required
    <state>          name kind description              child -> children (list), post (text),
                                                        transition -> transitions (list)
    <child>          ref                                bind -> bind (entries by 'variable', text)
    <transition>     name to sync                       condition (text)
    <synchronisation> name talk_timeout sync_timeout    transition -> transitions (names)
                     fail_on_timeout
    <plantype>       name description                   plan -> plans (names)
    <problem>        name wait_plan alternative_plan    element -> elements (names), object -> objects
                     update_time timeout planner description    (list), world goal (text)
    <variable>, <parameter>, <object>: name type min max candidates  (a typed name: ``name - type``,
                     ``name - type[min, max]`` or ``{name, type, range: [min, max], candidates}`` in YAML)
    <predicate>, <function>: name arity doc  (``name/arity`` or ``{name, arity, doc}`` in YAML)

Shapes:

* **list**: repeated elements, each read as a mapping, form a list.
* **names**: repeated elements, each holding text, form a list of texts.
* **entries**: repeated elements form one mapping; each names its key by an
  attribute (``<priority task="Explore" value="0.9"/>``,
  ``<bind variable="goal">pos(a)</bind>``); the value is the ``value``
  attribute or the element's text.
* **one**: a single element read as a mapping (``<utility>``, ``<signature>``).
* **value**: a single element read like the value of a behaviour's ``<param>``
  (``<default>0.3</default>``, ``<default type="str">1</default>``,
  ``<default><item>0</item><item>0</item></default>``).
* **text**: a single element holding text: formulas and descriptions. Write
  ``<`` and ``&`` as ``&lt;`` and ``&amp;`` or put the text in
  ``<![CDATA[...]]>``; the text's place is kept, so a formula error points at
  the right file column.

Any key may be given either way: ``description="..."`` or
``<description>...</description>``, ``<transition to="B" condition="x"/>``.
The same key given twice (two ``<pre>``, or an attribute and an element) is
reported as a duplicate. Elements and attributes the table does not know are
kept as keys of the same name, so the builder reports them as unknown keys
with their places; nothing is dropped silently (text, attributes or elements
where a text element or an entry allows none are reported by the reader).
Only ``xsi:*`` attributes on ``<alica>`` (schema hints for editors) are ignored.
Positions come from the raw text: every element, attribute and text keeps its
1-based line and column.

Behaviour parameters (``<param name="tolerance" value="0.3"/>``) are untyped,
as in YAML: the text is resolved by YAML 1.1 rules (int, float, bool, null,
else text), so ``value="0.3"`` is the number 0.3. ``type="str"`` keeps the
text as text; a list is written as ``<item>`` children (``type="list"`` for an
empty list); an item is written like a parameter without a name
(``<item>1</item>``, ``<item type="str">true</item>``); no value means null.

Skill declarations (``skills:`` in YAML, :mod:`alica.io.skill_declarations`)::

    <skill name="Attack" doc="imported from the ALICA Plan Designer">
      <capability>arm</capability>
      <parameter name="goal" type="str" required="false" default="" doc="where to go"/>
      <parameter name="corner" type="position" required="false"><default><item>0</item><item>0</item></default></parameter>
    </skill>

A parameter's ``default="..."`` attribute is read by the parameter's type:
a float, int or bool default by YAML 1.1 scalar rules (``default="0.3"`` is
0.3, ``default="true"`` is true), any other type's as text. A default the
attribute cannot hold (a list, a number of an ``any`` parameter) is written as
a ``<default>`` element.

Numbers, flags and cardinalities are attribute text; the builder reads
numeric text (``frequency="10"``, ``max="*"``, ``success_required="true"``).

Safety: DOCTYPEs (and so entity declarations) are refused before parsing,
entities are never expanded, nothing is fetched from the network.

Not expressible in XML: an empty list that must be present (``states: []``)
reads as missing; characters XML 1.0 forbids (most control characters)
cannot be written (:func:`write_xml` raises ``ValueError``).
"""

from __future__ import annotations

import bisect
import codecs
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from lxml import etree

from alica.io.tree import Node
from alica.io.xml_vocabulary import (
    _ENTRIES,
    _NEWLINE,
    _SPECS,
    _XML_NS,
    _XSI,
    ENTRIES,
    LIST,
    NAMES,
    ONE,
    TEXT,
    VALUE,
    resolve_scalar,
)
from alica.io.xml_write import write_xml
from alica.source import Diagnostic, SourceSpan, byte_place

__all__ = ["read_xml", "resolve_scalar", "write_xml"]


# --------------------------------------------------------------------------- reading


@dataclass
class _Tag:
    """A start tag found in the raw text."""

    name: str
    start: int
    end: int  # index just after '>'
    attributes: dict[str, tuple[int, int, int]]  # raw name -> (name index, value index, closing quote index)


_TAG_NAME = re.compile(r"[^\s/>]+")
_ATTRIBUTE = re.compile(r"\s*([^\s=/>]+)\s*=\s*([\"'])")
_TAG_CLOSE = re.compile(r"\s*/?>")


def _scan_tags(text: str) -> list[_Tag]:
    """Every start tag of well-formed XML text, in document order, with places."""
    tags: list[_Tag] = []
    i = 0
    while True:
        j = text.find("<", i)
        if j < 0:
            return tags
        for opening, closing in (("<!--", "-->"), ("<![CDATA[", "]]>"), ("<?", "?>"), ("</", ">"), ("<!", ">")):
            if text.startswith(opening, j):
                k = text.find(closing, j + len(opening))
                if k < 0:
                    return tags
                i = k + len(closing)
                break
        else:
            name = _TAG_NAME.match(text, j + 1)
            if name is None:
                return tags
            pos = name.end()
            attributes: dict[str, tuple[int, int, int]] = {}
            while True:
                attribute = _ATTRIBUTE.match(text, pos)
                if attribute is not None:
                    end = text.find(attribute.group(2), attribute.end())
                    if end < 0:
                        return tags
                    attributes.setdefault(attribute.group(1), (attribute.start(1), attribute.end(), end))
                    pos = end + 1
                    continue
                close = _TAG_CLOSE.match(text, pos)
                if close is None:
                    return tags
                pos = close.end()
                break
            tags.append(_Tag(name.group(), j, pos, attributes))
            i = pos


_REFERENCE = re.compile(r"&(#x[0-9a-fA-F]+|#[0-9]+|lt|gt|amp|quot|apos);|[\t\n\r]")
_NAMED = {"lt": "<", "gt": ">", "amp": "&", "quot": '"', "apos": "'"}


def _attribute_value(raw: str) -> str:
    """An attribute value as the parser reports it: references replaced, blanks normalised (XML 1.0, 3.3.3).

    Reading values from the raw text keeps an element with 10^5 attributes linear:
    lxml's ``el.attrib.items()`` (and ``el.get``) walk the attribute list for every value.
    """

    def replace(match: re.Match[str]) -> str:
        ref = match.group(1)
        if ref is None:
            return " "
        if ref.startswith("#x"):
            return chr(int("0" + ref[1:], 0))  # "#x41" -> "0x41"
        if ref.startswith("#"):
            return chr(int(ref[1:]))
        return _NAMED[ref]

    return _REFERENCE.sub(replace, raw) if "&" in raw or "\t" in raw or "\n" in raw or "\r" in raw else raw


def _prolog_declaration(text: str) -> int | None:
    """Where a ``<!DOCTYPE`` (or other ``<!`` declaration) starts before the root element."""
    i, n = 0, len(text)
    while i < n:
        while i < n and text[i] in " \t\r\n\ufeff":
            i += 1
        if text.startswith("<?", i):
            k = text.find("?>", i + 2)
            if k < 0:
                return None
            i = k + 2
        elif text.startswith("<!--", i):
            k = text.find("-->", i + 4)
            if k < 0:
                return None
            i = k + 3
        elif text.startswith("<!", i) and not text.startswith("<![", i):
            return i
        else:
            return None
    return None


_HINTS: tuple[tuple[tuple[str, ...], str], ...] = (
    (("doctype", "dtd", "entitydecl"), "remove the <!DOCTYPE ...> block; plan files take no DTD"),
    (
        ("entity", "entityref"),
        "write '&' as &amp;; only &lt; &gt; &amp; &quot; &apos; and character references like &#60; are defined",
    ),
    (
        ("invalid element name", "starttag", "unescaped '<'", "'<' not allowed"),
        "write '<' in a formula as &lt; (and '&' as &amp;), or put the formula inside <![CDATA[ ... ]]>",
    ),
    (
        ("mismatch", "premature end", "endtag", "end of data", "not closed"),
        "close every element: each <tag> needs a matching </tag>, or write it as <tag/>",
    ),
    (("extra content",), "a plan file holds exactly one <alica> element; put every section inside it"),
    (
        ("document is empty", "start tag expected"),
        'start the file with <alica version="1"> (after an optional <?xml ...?> line)',
    ),
    (("redefined",), "give each attribute once"),
    (
        ("specification mandates value", "attributes construct", "couldn't find end of start tag", "attvalue", "quote"),
        'write attributes as name="value"',
    ),
    (("char", "encoding", "input is not proper"), "remove the control character or save the file as UTF-8"),
)


def _hint_for(message: str) -> str:
    lowered = message.lower()
    for words, hint in _HINTS:
        if any(w in lowered for w in words):
            return hint
    return "fix the XML syntax at this place"


def _decode(data: bytes, path: str) -> tuple[str | None, Diagnostic | None]:
    """Bytes as text: by byte-order mark, then the XML declaration, else UTF-8."""
    encoding = "utf-8"
    for bom, name in (
        (codecs.BOM_UTF8, "utf-8-sig"),
        (codecs.BOM_UTF32_LE, "utf-32"),
        (codecs.BOM_UTF32_BE, "utf-32"),
        (codecs.BOM_UTF16_LE, "utf-16"),
        (codecs.BOM_UTF16_BE, "utf-16"),
    ):
        if data.startswith(bom):
            encoding = name
            break
    else:
        declared = re.match(rb"<\?xml[^>]*?encoding\s*=\s*[\"']([A-Za-z0-9._-]+)[\"']", data)
        if declared:
            encoding = declared.group(1).decode("ascii")
    try:
        return data.decode(encoding), None
    except LookupError:
        return None, Diagnostic(SourceSpan(path, 1, 1), f"unknown encoding '{encoding}'", "save the file as UTF-8")
    except (UnicodeError, ValueError) as exc:
        span = SourceSpan(path, 1, 1)
        if isinstance(exc, UnicodeDecodeError):
            if encoding.lower().replace("_", "-") in ("utf-8", "utf8", "utf-8-sig", "ascii"):
                span = byte_place(data, exc.start, path)  # lines end in b"\n" only in these encodings
            at = f" (byte 0x{data[exc.start]:02x})" if exc.start < len(data) else ""
        else:
            at = ""
        message = f"the file is not valid {encoding} text{at}"
        return None, Diagnostic(span, message, "save the file as UTF-8")


def _parser() -> etree.XMLParser:
    return etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=False,
        remove_comments=True,
        remove_pis=True,
        encoding="utf-8",
    )


def read_xml(text: str | bytes, path: str) -> tuple[Node | None, list[Diagnostic]]:
    """Parse one XML plan file into a located tree.

    Args:
        text: the file's contents (bytes are decoded by BOM, XML declaration, else UTF-8).
        path: the name used in diagnostics.

    Returns:
        The tree (``None`` if the file could not be read) and the problems found.
    """
    if isinstance(text, (bytes, bytearray)):
        decoded, problem = _decode(bytes(text), path)
        if decoded is None:
            return None, [problem] if problem else []
        text = decoded
    try:
        return _read(text, path)
    except RecursionError:
        return None, [Diagnostic(SourceSpan(path, 1, 1), "the XML nests too deeply", "flatten the elements")]


def _read(text: str, path: str) -> tuple[Node | None, list[Diagnostic]]:
    text = text.removeprefix("\ufeff")
    # XML reads every line end as '\n' anyway; libxml2 would not count a lone '\r' as a line.
    text = _NEWLINE.sub("\n", text)
    reader = _Reader(text, path)
    declaration = _prolog_declaration(text)
    if declaration is not None:
        return None, [reader.dtd_problem(reader.at(declaration))]
    try:
        data = text.encode("utf-8")
    except UnicodeEncodeError as exc:
        message = "the text holds a character that is not valid Unicode (a lone surrogate)"
        return None, [Diagnostic(reader.at(exc.start), message, "remove the character")]
    try:
        root = etree.fromstring(data, _parser())
    except etree.XMLSyntaxError as exc:
        return None, [reader.syntax_problem(exc)]
    except (etree.LxmlError, ValueError) as exc:
        return None, [Diagnostic(SourceSpan(path, 1, 1), f"XML: {exc}", "fix the XML syntax")]
    if root is None:
        return None, [
            Diagnostic(
                SourceSpan(path, 1, 1), "the file holds no XML element", 'start the file with <alica version="1">'
            )
        ]
    docinfo = root.getroottree().docinfo
    if docinfo.doctype or docinfo.internalDTD is not None or docinfo.externalDTD is not None:
        return None, [reader.dtd_problem(SourceSpan(path, 1, 1))]
    reader.locate(root)
    for entity in root.iter(etree.Entity):
        parent = entity.getparent()
        span = reader.span(parent) if parent is not None else SourceSpan(path, 1, 1)
        hint = "only &lt; &gt; &amp; &quot; &apos; and character references like &#60; are defined"
        return None, [Diagnostic(span, f"undefined entity reference {entity.text}", hint)]
    if _raw_name(root) != "alica":
        return None, [
            Diagnostic(
                reader.span(root),
                f"the root element must be <alica>, not <{_raw_name(root)}>",
                'wrap the plan file in <alica version="1"> ... </alica> (without a namespace)',
            )
        ]
    tree = reader.mapping(root, "alica", root=True)
    return tree, reader.diagnostics


def _raw_name(el: Any) -> str:
    """The tag as written (``p:name`` for prefixed names)."""
    qname = etree.QName(el)
    if qname.namespace is None:
        return qname.localname
    return f"{el.prefix}:{qname.localname}" if el.prefix else f"{{{qname.namespace}}}{qname.localname}"


def _raw_attribute(el: Any, key: str) -> tuple[str, str | None]:
    """An attribute key as written and its namespace."""
    if not key.startswith("{"):
        return key, None
    namespace, local = key[1:].split("}", 1)
    if namespace == _XML_NS:
        return f"xml:{local}", namespace
    for prefix, uri in (el.nsmap or {}).items():
        if uri == namespace and prefix:
            return f"{prefix}:{local}", namespace
    return key, namespace


def _blank(text: str | None) -> bool:
    return text is None or not text.strip()


class _Reader:
    """Turns a parsed element tree into located nodes."""

    def __init__(self, text: str, path: str) -> None:
        self.text = text
        self.path = path
        self.diagnostics: list[Diagnostic] = []
        self.line_starts = [0] + [m.end() for m in _NEWLINE.finditer(text)]
        self.lines: list[str] | None = None
        self.places: dict[Any, _Tag] = {}
        self.elements: list[Any] = []

    # -- places

    def at(self, index: int) -> SourceSpan:
        """The 1-based line and column of a character index of the text."""
        line = bisect.bisect_right(self.line_starts, index)
        return SourceSpan(self.path, max(line, 1), index - self.line_starts[max(line, 1) - 1] + 1)

    def locate(self, root: Any) -> None:
        """Pair every element with its start tag in the raw text."""
        self.elements = list(root.iter(etree.Element))
        try:
            tags = _scan_tags(self.text)
        except Exception:
            tags = []
        if len(tags) == len(self.elements) and all(
            t.name.rsplit(":", 1)[-1] == etree.QName(e).localname for t, e in zip(tags, self.elements)
        ):
            self.places = dict(zip(self.elements, tags))

    def span(self, el: Any) -> SourceSpan:
        """Where an element's start tag begins."""
        tag = self.places.get(el)
        if tag is not None:
            return self.at(tag.start)
        return self._fallback(el)

    def _fallback(self, el: Any) -> SourceSpan:
        """``sourceline`` (where the start tag ends) and a search for ``<tag`` back from there."""
        if self.lines is None:
            self.lines = [self.text[s:e] for s, e in zip(self.line_starts, self.line_starts[1:] + [len(self.text)])]
        line = el.sourceline if isinstance(el.sourceline, int) and el.sourceline >= 1 else 1
        line = min(line, max(len(self.lines), 1))
        needle = "<" + _raw_name(el)
        for number in range(line, max(line - 50, 0), -1):
            if number - 1 < len(self.lines):
                column = self.lines[number - 1].find(needle)
                if column >= 0:
                    return SourceSpan(self.path, number, column + 1)
        return SourceSpan(self.path, line, 1)

    def text_start(self, el: Any) -> SourceSpan | None:
        """Where an element's text content starts (after '>' and any '<![CDATA[')."""
        tag = self.places.get(el)
        if tag is None:
            return None
        index = tag.end
        while True:
            if self.text.startswith("<!--", index):
                k = self.text.find("-->", index)
                index = k + 3 if k >= 0 else index
            elif self.text.startswith("<?", index):
                k = self.text.find("?>", index)
                index = k + 2 if k >= 0 else index
            else:
                break
            if k < 0:
                break
        if self.text.startswith("<![CDATA[", index):
            index += len("<![CDATA[")
        return self.at(index)

    def attributes(self, el: Any) -> Iterator[tuple[str, str | None, str, SourceSpan, SourceSpan]]:
        """``(name as written, namespace, value, name span, value span)`` in document order."""
        tag = self.places.get(el)
        start: int | None = None
        for key in el.keys():  # keys(): linear; values are read from the raw text where it is located
            name, namespace = _raw_attribute(el, key)
            where = tag.attributes.get(name) if tag is not None else None
            if where is not None:
                value = _attribute_value(self.text[where[1] : where[2]])
                yield name, namespace, value, self.at(where[0]), self.at(where[1])
                continue
            value = el.get(key) or ""
            if start is None:  # best effort: 'name=' after the element's '<tag'
                span = self.span(el)
                start = self.line_starts[min(span.line, len(self.line_starts)) - 1] + span.column - 1
            found = re.compile(rf"\s({re.escape(name)})\s*=\s*[\"']").search(self.text, start)
            if found is None:
                span = self.span(el)
                yield name, namespace, value, span, span
            else:
                yield name, namespace, value, self.at(found.start(1)), self.at(found.end())

    # -- problems

    def problem(self, span: SourceSpan, message: str, hint: str = "") -> None:
        self.diagnostics.append(Diagnostic(span, message, hint))

    def dtd_problem(self, span: SourceSpan) -> Diagnostic:
        return Diagnostic(
            span,
            "DTDs and entity declarations are not allowed in plan files",
            "remove the <!DOCTYPE ...> block; write special characters as &lt; &gt; &amp; &quot; &apos; or &#NNN;",
        )

    def syntax_problem(self, exc: etree.XMLSyntaxError) -> Diagnostic:
        line, column = 1, 1
        position = getattr(exc, "position", None)
        if isinstance(position, tuple) and len(position) == 2:
            line, column = position
        line = min(max(int(line or 1), 1), len(self.line_starts))
        start = self.line_starts[line - 1]
        end = self.line_starts[line] if line < len(self.line_starts) else len(self.text)
        column = min(max(int(column or 1), 1), max(end - start, 0) + 1)
        message = " ".join(str(getattr(exc, "msg", "") or exc).split())
        message = re.sub(r",?\s*line \d+, column \d+\s*$", "", message).strip() or "malformed XML"
        return Diagnostic(SourceSpan(self.path, line, column), f"XML syntax: {message}", _hint_for(message))

    # -- nodes

    def text_node(self, el: Any) -> Node:
        """An element's text as a string node located at its first character."""
        text = el.text
        if text is None:
            return Node("", self.span(el))
        start = self.text_start(el)
        if start is None:
            return Node(text, self.span(el))
        return Node(text, start, text_offset=(start.line, start.column))

    def value_node(self, value: str, span: SourceSpan) -> Node:
        """An attribute value as a string node."""
        return Node(value, span, text_offset=(span.line, span.column))

    def mapping(self, el: Any, spec_name: str, root: bool = False) -> Node:
        """A mapping element read by its spec."""
        spec = _SPECS[spec_name]
        tag = _raw_name(el)
        items: dict[str, Node] = {}
        key_spans: dict[str, SourceSpan] = {}
        put = self._putter(tag, items, key_spans)
        for name, namespace, value, name_span, value_span in self.attributes(el):
            if root and namespace == _XSI:
                continue  # xsi:noNamespaceSchemaLocation and friends: for editors, not data
            put(spec.key_of(name), self.value_node(value, value_span), name_span)
        children = list(el.iterchildren(etree.Element))
        if spec.content and not children:
            if not _blank(el.text) or spec.content not in items:
                put(spec.content, self.text_node(el), self.text_start(el) or self.span(el))
        else:
            self._no_text(el, tag, children)
        collections: dict[str, Node] = {}
        for child in children:
            child_tag = _raw_name(child)
            child_span = self.span(child)
            known = spec.child(child_tag)
            if known is None:
                put(child_tag, self.generic(child), child_span)
            elif known.shape == ONE:
                put(known.key, self.mapping(child, known.spec), child_span)
            elif known.shape == TEXT:
                put(known.key, self.text_element(child), child_span)
            elif known.shape == VALUE:
                attributes = {name: (value, at, value_at) for name, _, value, at, value_at in self.attributes(child)}
                put(known.key, self.typed_value(child, child_tag, attributes), child_span)
            else:
                collection = collections.get(known.key)
                if collection is None:
                    collection = Node({} if known.shape == ENTRIES else [], child_span)
                    collections[known.key] = collection
                    put(known.key, collection, child_span)
                if known.shape == LIST:
                    collection.value.append(self.mapping(child, known.spec))  # type: ignore[union-attr]
                elif known.shape == NAMES:
                    collection.value.append(self.text_element(child, known.attribute))  # type: ignore[union-attr]
                else:
                    self.entry(child, known.spec, collection)
        return Node(items, self.span(el), key_spans)

    def _putter(
        self, tag: str, items: dict[str, Node], key_spans: dict[str, SourceSpan]
    ) -> Callable[[str, Node, SourceSpan], None]:
        def put(key: str, node: Node, key_span: SourceSpan) -> None:
            if key in items:
                self.problem(
                    key_span,
                    f"duplicate '{key}' in <{tag}> (first given at line {key_spans[key].line})",
                    "give it once, as an attribute or as one element",
                )
                return
            items[key] = node
            key_spans[key] = key_span

        return put

    def _no_text(self, el: Any, tag: str, children: list[Any]) -> None:
        """Report text written where only attributes and elements belong."""
        pieces = [(el.text, self.text_start(el) or self.span(el))]
        pieces += [(child.tail, self.span(child)) for child in children]
        for text, span in pieces:
            if not _blank(text):
                shown = " ".join(text.split())
                shown = shown if len(shown) <= 30 else shown[:27] + "..."
                self.problem(
                    span,
                    f"text '{shown}' is not allowed directly inside <{tag}>",
                    "put it in an attribute or in a child element such as <description>",
                )
                return

    def text_element(self, el: Any, attribute: str = "") -> Node:
        """An element that holds text (a formula, a description, a name)."""
        tag = _raw_name(el)
        node: Node | None = None
        for name, _, value, name_span, value_span in self.attributes(el):
            if attribute and name == attribute:
                node = self.value_node(value, value_span)
            else:
                also = f" or a '{attribute}' attribute" if attribute else ""
                self.problem(name_span, f"unknown attribute '{name}' on <{tag}>", f"<{tag}> holds only text{also}")
        for child in el.iterchildren(etree.Element):
            self.problem(
                self.span(child),
                f"<{tag}> holds only text, not a <{_raw_name(child)}> element",
                "write '<' in text as &lt;, or put the text inside <![CDATA[ ... ]]>",
            )
        if node is not None:
            if not _blank(el.text):
                self.problem(self.span(el), f"<{tag}> has both a '{attribute}' attribute and text", "keep one of them")
            return node
        return self.text_node(el)

    def generic(self, el: Any) -> Node:
        """An element the table does not know: its text, or a mapping of what it holds."""
        tag = _raw_name(el)
        children = list(el.iterchildren(etree.Element))
        if not el.attrib and not children:
            return self.text_node(el)
        items: dict[str, Node] = {}
        key_spans: dict[str, SourceSpan] = {}
        put = self._putter(tag, items, key_spans)
        for name, _, value, name_span, value_span in self.attributes(el):
            put(name, self.value_node(value, value_span), name_span)
        self._no_text(el, tag, children)
        for child in children:
            put(_raw_name(child), self.generic(child), self.span(child))
        return Node(items, self.span(el), key_spans)

    def entry(self, el: Any, kind: str, table: Node) -> None:
        """One element of an entries collection, added to ``table``."""
        entry = _ENTRIES[kind]
        tag = _raw_name(el)
        attributes = {
            name: (value, name_span, value_span) for name, _, value, name_span, value_span in self.attributes(el)
        }
        key = attributes.pop(entry.key, None)
        if entry.typed:
            node = self.typed_value(el, tag, attributes)
        else:
            node = self.entry_text(el, tag, attributes, entry.key)
        if key is None:
            self.problem(
                self.span(el), f"<{tag}> has no '{entry.key}' attribute", f'write <{tag} {entry.key}="..." ...>'
            )
            return
        mapping: dict[str, Node] = table.value  # type: ignore[assignment]
        if key[0] in mapping:
            self.problem(
                self.span(el),
                f"duplicate <{tag}> for '{key[0]}' (first given at line {table.key_spans[key[0]].line})",
                "give each once",
            )
            return
        mapping[key[0]] = node
        table.key_spans[key[0]] = self.span(el)

    def entry_text(
        self, el: Any, tag: str, attributes: dict[str, tuple[str, SourceSpan, SourceSpan]], key: str
    ) -> Node:
        """The value of a priority or binding: its ``value`` attribute or its text."""
        given = attributes.pop("value", None)
        for name, (_, name_span, _) in attributes.items():
            self.problem(name_span, f"unknown attribute '{name}' on <{tag}>", f"<{tag}> takes '{key}' and 'value'")
        for child in el.iterchildren(etree.Element):
            self.problem(
                self.span(child),
                f"<{tag}> holds only text, not a <{_raw_name(child)}> element",
                "write '<' in text as &lt;, or use <![CDATA[ ... ]]>",
            )
        if given is not None:
            if not _blank(el.text):
                self.problem(self.span(el), f"<{tag}> has both a 'value' attribute and text", "keep one of them")
            return self.value_node(given[0], given[2])
        return self.text_node(el)

    def typed_value(self, el: Any, tag: str, attributes: dict[str, tuple[str, SourceSpan, SourceSpan]]) -> Node:
        """A parameter value: YAML-typed text, ``type="str"`` text, or a list of ``<item>``."""
        kind_attribute = attributes.pop("type", None)
        given = attributes.pop("value", None)
        for name, (_, name_span, _) in attributes.items():
            takes = "'name', 'value' and 'type'" if tag == "param" else "'value' and 'type'"
            self.problem(name_span, f"unknown attribute '{name}' on <{tag}>", f"<{tag}> takes {takes}")
        kind = None
        if kind_attribute is not None:
            kind = kind_attribute[0].strip()
            if kind not in ("str", "list"):
                self.problem(
                    kind_attribute[2],
                    f"unknown value type '{kind}' on <{tag}>",
                    'use type="str" to keep text as text, or type="list" for a list',
                )
                kind = None
        items = []
        for child in el.iterchildren(etree.Element):
            if _raw_name(child) == "item":
                items.append(child)
            else:
                self.problem(
                    self.span(child),
                    f"<{tag}> holds <item> elements only, not <{_raw_name(child)}>",
                    "write list values as <item>...</item>",
                )
        if items or kind == "list":
            if given is not None:
                self.problem(
                    given[1], f"<{tag}> holds a list, so it takes no 'value' attribute", "put every value in an <item>"
                )
            self._no_text(el, tag, items)
            return Node([self.item(child) for child in items], self.span(el))
        if given is not None:
            if not _blank(el.text):
                self.problem(self.span(el), f"<{tag}> has both a 'value' attribute and text", "keep one of them")
            text, span = given[0], given[2]
        elif el.text is not None:
            start = self.text_start(el)
            text, span = el.text, start or self.span(el)
        else:
            return Node(None, self.span(el))
        value = text if kind == "str" else resolve_scalar(text)
        if isinstance(value, str):
            return Node(value, span, text_offset=(span.line, span.column))
        return Node(value, span)

    def item(self, el: Any) -> Node:
        """One ``<item>`` of a list value."""
        attributes = {
            name: (value, name_span, value_span) for name, _, value, name_span, value_span in self.attributes(el)
        }
        return self.typed_value(el, "item", attributes)
