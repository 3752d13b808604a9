"""Each technique's defaults are stated once: its registry option table.

A technique class is configured by the registry from its option table (the family's
vtkPenumbra*Techniques.cxx); a C++ or Python user may also create the class directly. Both must
give the same technique, so a class constructed by hand must print (PrintSelf) exactly what the
registry makes of an empty option set. PrintSelf is the comparison, so every option must show
in it: setting any option to another valid value must change what the technique prints, or the
option does not reach the technique at all.
"""

import json
import re
import unittest

import penumbra
from vtkmodules.vtkRenderingCore import vtkRenderer

Techniques = penumbra.vtkPenumbraTechniques

# What PrintSelf prints that is not a setting: object bookkeeping and addresses.
NOT_A_SETTING = re.compile(r"Modified Time|Reference Count|Debug|Registered Events|0x[0-9a-f]+")


def settings(technique):
    return [line.strip() for line in str(technique).splitlines()
            if line.strip() and not NOT_A_SETTING.search(line)]


def installed(name, options):
    """The technique the registry installs for `name` with the options dict, or the error."""
    renderer = vtkRenderer()
    registry = Techniques()
    if not registry.Apply(renderer, name, json.dumps(options)):
        return None, registry.GetErrorMessage()
    shadows = penumbra.shadow_pass(renderer)
    return (shadows.GetTechnique() if shadows else None), ""


def other_value(name, index):
    """A valid value of option `index` of technique `name` other than its default."""
    default = json.loads(Techniques.GetOptionDefault(name, index))
    kind = Techniques.GetOptionType(name, index)
    values = Techniques.GetOptionRange(name, index)
    if kind == "boolean":
        return not default
    if ".." in values:
        low, high = (float(v) for v in values.split(".."))
        value = high if default != high else low
        return int(value) if kind == "integer" else value
    return [v for v in json.loads("[" + values + "]") if v != default][0]


def penumbra_techniques():
    """Registry names whose technique is a Penumbra class (not none, not VTK's pass)."""
    names = []
    for i in range(Techniques.GetNumberOfTechniques()):
        name = Techniques.GetTechniqueName(i)
        technique, _ = installed(name, {})
        if technique is not None:
            names.append(name)
    return names


class TechniqueDefaultsTest(unittest.TestCase):
    def test_every_option_reaches_the_technique(self):
        names = penumbra_techniques()
        self.assertGreaterEqual(len(names), 13, names)
        for name in names:
            defaults = settings(installed(name, {})[0])
            for index in range(Techniques.GetNumberOfOptions(name)):
                option = Techniques.GetOptionName(name, index)
                value = other_value(name, index)
                with self.subTest(technique=name, option=option, value=value):
                    technique, error = installed(name, {option: value})
                    self.assertIsNotNone(technique, error)
                    self.assertNotEqual(settings(technique), defaults,
                                        "%s=%r changes nothing the technique prints"
                                        % (option, value))

    def test_a_class_made_by_hand_has_its_tables_defaults(self):
        # A class with several registry modes (shadowmap/resm/pcss/single-sample-soft,
        # raytraced/adaptive-soft, llsm/llsm-hybrid) has the defaults of the mode it names
        # itself after when constructed; the other modes differ from it by their mode switch.
        compared = 0
        for name in penumbra_techniques():
            technique, _ = installed(name, {})
            by_hand = technique.NewInstance()
            if by_hand.GetTechniqueName() != name:
                continue
            with self.subTest(technique=name):
                self.assertEqual(settings(by_hand), settings(technique))
                compared += 1
        self.assertGreaterEqual(compared, 9)


if __name__ == "__main__":
    unittest.main()
