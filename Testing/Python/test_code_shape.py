"""The shape of the code: files of one subject and functions of one phase. No C++ source file
over 1,200 lines and no function body over 150 lines, in C++ or GLSL, anywhere under
Modules, CLI and Wrapping; the module dependencies of the vtk.module files point down the
layers only (no technique family uses another); and the contract (Modules/Shadows) names no
technique."""

import os
import re
import unittest

from penumbra_testing import SOURCE_DIR

MAX_FILE_LINES = 1200
MAX_FUNCTION_LINES = 150
ROOTS = ("Modules", "CLI", "Wrapping")

# A function head: a name followed by a parameter list at the end of the text before "{".
HEAD = re.compile(r"[\w:~<>,\s\*&\[\]]+\([^;{}]*\)\s*(const|override|noexcept|final|\s)*"
                  r"(->[^{;]*)?\s*$", re.S)
NOT_A_FUNCTION = re.compile(r"\b(if|for|while|switch|catch|namespace|class|struct|enum|union|"
                            r"do|else)\b[^;{}]*$")


def strip_comments_and_strings(text):
    """`text` with comments and string literals blanked, newlines kept (line numbers hold)."""
    out, i, n = [], 0, len(text)
    while i < n:
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
        elif text[i] in "\"'":
            quote, j = text[i], i + 1
            while j < n and text[j] != quote:
                j += 2 if text[j] == "\\" else 1
            out.append(quote + quote)
            i = j + 1
        else:
            out.append(text[i])
            i += 1
    return "".join(out)


def long_functions(path):
    """(line, length, head) of every function body in `path` longer than the limit."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = strip_comments_and_strings(f.read())
    found, stack, line, statement_start = [], [], 1, 0
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        elif c == "{":
            head = text[statement_start:i].strip()[-300:]
            is_function = bool(HEAD.search(head)) and not NOT_A_FUNCTION.search(head)
            stack.append((line, is_function, head[-60:].replace("\n", " ")))
            statement_start = i + 1
        elif c == "}":
            if stack:
                start, is_function, head = stack.pop()
                if is_function and line - start > MAX_FUNCTION_LINES:
                    found.append((start, line - start, head))
            statement_start = i + 1
        elif c == ";":
            statement_start = i + 1
    return found


def sources(extensions):
    for root in ROOTS:
        for folder, _, names in os.walk(os.path.join(SOURCE_DIR, root)):
            for name in sorted(names):
                if name.endswith(extensions):
                    yield os.path.join(folder, name)


class CodeShapeTest(unittest.TestCase):
    def test_files_of_one_subject(self):
        big = []
        for path in sources((".cxx",)):
            with open(path, encoding="utf-8", errors="replace") as f:
                lines = sum(1 for _ in f)
            if lines > MAX_FILE_LINES:
                big.append("%s (%d lines)" % (os.path.relpath(path, SOURCE_DIR), lines))
        self.assertEqual(big, [], "files over %d lines" % MAX_FILE_LINES)

    def test_functions_of_one_phase(self):
        long = []
        for path in sources((".cxx", ".h", ".glsl")):
            for start, length, head in long_functions(path):
                long.append("%s:%d %d lines (%s)" % (os.path.relpath(path, SOURCE_DIR), start,
                                                      length, head))
        self.assertEqual(long, [], "function bodies over %d lines" % MAX_FUNCTION_LINES)

    def test_layers_point_down(self):
        # name -> its dependencies on Penumbra modules (DEPENDS and PRIVATE_DEPENDS).
        deps = {}
        for folder in sorted(os.listdir(os.path.join(SOURCE_DIR, "Modules"))):
            path = os.path.join(SOURCE_DIR, "Modules", folder, "vtk.module")
            if not os.path.exists(path):
                continue
            section, uses = None, set()
            with open(path) as f:
                for line in f:
                    word = line.strip()
                    if line[:1].isalpha():
                        section = word
                    elif (section in ("DEPENDS", "PRIVATE_DEPENDS")
                          and word.startswith("Penumbra::")):
                        uses.add(word[len("Penumbra::"):])
            deps[folder] = uses
        layer = {"Scene": 0, "Sources": 0, "SceneIO": 1, "RayTracing": 1, "Headless": 1,
                 "Analysis": 2, "Shadows": 2, "ShadowMaps": 3, "ExactShadows": 3, "Gears": 3,
                 "Techniques": 4}
        self.assertEqual(set(deps), set(layer), "a module without a layer, or a layer gone")
        upward = ["%s -> %s" % (m, d) for m, uses in deps.items() for d in sorted(uses)
                  if layer[d] >= layer[m]]
        self.assertEqual(upward, [], "dependencies that do not point down")

    def test_the_contract_names_no_technique(self):
        techniques = []
        for family in ("ShadowMaps", "ExactShadows", "Gears", "Techniques"):
            for name in os.listdir(os.path.join(SOURCE_DIR, "Modules", family)):
                if name.endswith("Shadows.h"):
                    techniques.append(name[:-2])
        self.assertIn("vtkPenumbraGearsShadows", techniques)
        named = []
        for path in sources((".cxx", ".h")):
            # Its tests may use any technique (through the registry).
            relative = os.path.relpath(path, os.path.join(SOURCE_DIR, "Modules", "Shadows"))
            if relative.startswith("..") or relative.startswith("Testing"):
                continue
            with open(path, encoding="utf-8") as f:
                text = strip_comments_and_strings(f.read())
            named += ["%s: %s" % (os.path.basename(path), t) for t in techniques
                      if re.search(r"\b%s\b" % t, text)]
        self.assertEqual(named, [], "the contract names technique classes")

    def test_the_checker_finds_a_long_function(self):
        # The checker itself: a function of 151 lines is found, one of 150 is not.
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            for body, expected in ((150, 0), (151, 1)):
                path = os.path.join(tmp, "x.cxx")
                with open(path, "w") as f:
                    f.write("int f(int a)\n{\n" + "  a += 1; // {\n" * (body - 1) + "}\n")
                self.assertEqual(len(long_functions(path)), expected, body)


if __name__ == "__main__":
    unittest.main()
