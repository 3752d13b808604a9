"""The shape of the code: files of one subject and functions of one phase. No C++ source file
over 1,200 lines and no function body over 150 lines, in C++ or GLSL, anywhere under
Modules, CLI and Wrapping; and no layer including a header of a layer above it (the module
dependencies of vtk.module files point down only)."""

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
