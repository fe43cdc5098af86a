// Display colours of labels by what they are: a structure name that the compiled-in rules know
// (Resources/Colors/anatomy_colors.csv: bone ivory, muscle red, fat yellow, arteries red, veins
// blue...) gets its class's colour, shaded by the label's value so that labels of one class stay
// distinct and each label keeps its colour from file to file.
//
// Before the rules, a reference colour table can give exact colours by name: 3D Slicer's own
// GenericAnatomyColors.txt (every Slicer installation ships it; Repose does not copy it, it
// finds it: findSlicerColorTable) or any Slicer colour table, named by $REPOSE_COLOR_TABLE or
// set in code.
#pragma once

#include "repose/volume/LabelTable.h"

#include <array>
#include <optional>
#include <string>

namespace repose {

// Slicer's colour table text, as vtkMRMLColorTableStorageNode reads a .ctbl or .txt: '#' comment
// lines, then "value name R G B [A]" per entry, colours 0-255, '_' in a name read as a space.
// Throws repose::Error "<source>: line N: <problem>" for a malformed line or a repeated value.
LabelTable parseColorTable(const std::string& text, const std::string& source);

// The reference colours: a label whose name (compared as the rules compare names) the table
// lists takes that entry's colour exactly. Process-wide, as Slicer's default colour node is; an
// empty table clears it. Unless set, the table $REPOSE_COLOR_TABLE names is read at the first
// colour asked for, or with that variable unset, Slicer's GenericAnatomyColors.txt when a Slicer
// installation is found (set but empty: no table, the rules alone); a file that cannot be read
// throws repose::Error naming it, then and at every later colour (never silently the other
// colours).
void setReferenceColors(const LabelTable& table);
// Back to the start: the table $REPOSE_COLOR_TABLE names (or Slicer's), read at the next colour
// asked for.
void useReferenceColorsFromEnvironment();
// Slicer's colour table `name` in a 3D Slicer installation, "" when none is found: the newest
// share/Slicer-X.Y/ColorFiles/<name> of $SLICER_HOME (Slicer's launcher sets it), else of the
// Slicer on the PATH, else of a Slicer* folder in /opt, /usr/local, ~, ~/Applications or
// /Applications (a macOS bundle's Contents too), the newest version among those.
std::string findSlicerColorTable(const std::string& name = "GenericAnatomyColors.txt");
// The reference colour of `name`, nullopt when the table does not list it.
std::optional<std::array<double, 3>> referenceColor(const std::string& name);

// The reference colour of `name` (variant 0), else the class colour of `name` shaded for `value`
// (RGB in [0,1]); nullopt when neither the reference table nor a rule knows it.
// `variant` > 0 gives other shades of the same class, for a table that must keep two labels
// apart whose shades came out alike (completeLabelNamesAndColors).
std::optional<std::array<double, 3>> anatomyColor(const std::string& name, int value,
                                                  int variant = 0);
// RGB in [0,1] of a hue in degrees (any real, wrapped), saturation and value in [0,1].
std::array<double, 3> hsvToRgb(double hueDeg, double saturation, double value);
// The rule that matched `name` ("" for none), for reports and tests.
std::string anatomyColorRule(const std::string& name);

}  // namespace repose
