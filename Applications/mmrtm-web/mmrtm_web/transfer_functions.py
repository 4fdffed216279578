"""The page's transfer-function editor: the points of a volume property's
scalar opacity and colour functions, as lists the page shows, and edits
of one point at a time."""


def hex_colour(rgb):
    return "#%02x%02x%02x" % tuple(max(0, min(255, round(255 * c))) for c in rgb)


def opacity_points(volume_property):
    """[{x, y}] of the property's scalar opacity function."""
    function = volume_property.GetScalarOpacity()
    points = []
    for index in range(function.GetSize()):
        node = [0.0] * 4
        function.GetNodeValue(index, node)
        points.append({"x": round(node[0], 3), "y": round(node[1], 4)})
    return points


def colour_points(volume_property):
    """[{x, colour}] of the property's colour function (colour as #rrggbb)."""
    function = volume_property.GetRGBTransferFunction()
    points = []
    for index in range(function.GetSize()):
        node = [0.0] * 6
        function.GetNodeValue(index, node)
        points.append({"x": round(node[0], 3), "colour": hex_colour(node[1:4])})
    return points


def set_opacity_point(volume_property, index, x=None, y=None):
    """Moves point `index` of the opacity function to value x and/or
    opacity y (clamped to 0..1). Returns False when the edit is not one
    (a bad index or number): the page may send anything."""
    function = volume_property.GetScalarOpacity()
    try:
        index = int(index)
        node = [0.0] * 4
        if not 0 <= index < function.GetSize():
            return False
        function.GetNodeValue(index, node)
        if x is not None:
            node[0] = float(x)
        if y is not None:
            node[1] = min(1.0, max(0.0, float(y)))
    except (TypeError, ValueError):
        return False
    if node[0] != node[0] or node[1] != node[1]:  # NaN
        return False
    function.SetNodeValue(index, node)  # which keeps the points sorted
    return True


def set_colour_point(volume_property, index, colour):
    """Sets the colour (#rrggbb) of point `index` of the colour function."""
    function = volume_property.GetRGBTransferFunction()
    try:
        index = int(index)
        if not 0 <= index < function.GetSize() or len(colour) != 7 or colour[0] != "#":
            return False
        rgb = [int(colour[i:i + 2], 16) / 255 for i in (1, 3, 5)]
    except (TypeError, ValueError):
        return False
    node = [0.0] * 6
    function.GetNodeValue(index, node)
    function.SetNodeValue(index, [node[0]] + rgb + node[4:6])
    return True

