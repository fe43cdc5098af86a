// Display colours of labels by what they are: a structure name that the compiled-in rules know
// (Resources/Colors/anatomy_colors.csv: bone ivory, muscle red, fat yellow, arteries red, veins
// blue...) gets its class's colour, shaded by the label's value so that labels of one class stay
// distinct and each label keeps its colour from file to file.
#pragma once

#include <array>
#include <optional>
#include <string>

namespace repose {

// The class colour of `name` shaded for `value` (RGB in [0,1]); nullopt when no rule matches.
// `variant` > 0 gives other shades of the same class, for a table that must keep two labels
// apart whose shades came out alike (completeLabelNamesAndColors).
std::optional<std::array<double, 3>> anatomyColor(const std::string& name, int value,
                                                  int variant = 0);
// RGB in [0,1] of a hue in degrees (any real, wrapped), saturation and value in [0,1].
std::array<double, 3> hsvToRgb(double hueDeg, double saturation, double value);
// The rule that matched `name` ("" for none), for reports and tests.
std::string anatomyColorRule(const std::string& name);

}  // namespace repose
