"""The colour legend of TMM Simulate's coloured stock: a bar of the colour band (-band .. 0 .. +band mm, the
colours of core.preview.deviation_colours.band_colours), its darkest ends standing for the cells beyond the band,
the band's values under it and a line with the extremes beyond it (how many cells, how far)."""
from __future__ import annotations

import numpy as np
from PySide import QtCore, QtGui

from tmm_workbench.core.preview.deviation_colours import BAND_INSIDE, NO_DESIGN_HEX, beyond_band, cmap

SIZE = (260, 14)
END = 18  # px of each end of the bar: the colour of the cells beyond the band


def _rgb(t: float) -> QtGui.QColor:
    return QtGui.QColor.fromRgbF(*map(float, cmap()(t)[:3]))


def bar_image(width: int, height: int) -> QtGui.QImage:
    """The bar: the beyond-band colour at each end (a block with a notch), the band's gradient between."""
    image = QtGui.QImage(width, height, QtGui.QImage.Format_RGB32)
    image.fill(QtGui.QColor("white"))
    painter = QtGui.QPainter(image)
    gradient = QtGui.QLinearGradient(END, 0, width - END, 0)
    lo, hi = BAND_INSIDE
    for s in np.linspace(0.0, 1.0, 33):
        gradient.setColorAt(float(s), _rgb(lo + (hi - lo) * float(s)))
    painter.fillRect(END, 0, width - 2 * END, height, QtGui.QBrush(gradient))
    painter.fillRect(0, 0, END - 2, height, _rgb(0.0))
    painter.fillRect(width - END + 2, 0, END - 2, height, _rgb(1.0))
    painter.end()
    return image


def signed(value: float) -> str:
    return f"{value:+.4f}"


class DeviationLegend:
    """The legend's widgets (names for tests and macros: colourBar, legendMin, legendZero, legendMax,
    legendBeyond, legendTitle); `show` writes a band and a deviation into them."""

    def __init__(self) -> None:
        self.widget = QtGui.QWidget()
        self.widget.setObjectName("legend")
        v = QtGui.QVBoxLayout(self.widget)
        v.setContentsMargins(0, 0, 0, 4)
        self.title = QtGui.QLabel("Colours of the stock in the 3D view: deviation, mm")
        self.title.setObjectName("legendTitle")
        self.title.setWordWrap(True)
        v.addWidget(self.title)
        bar = QtGui.QLabel()
        bar.setObjectName("colourBar")
        bar.setPixmap(QtGui.QPixmap.fromImage(bar_image(*SIZE)))
        bar.setToolTip("Inside the band: blue below the design, white on it, red above; "
                       "the darkest ends: beyond the band")
        v.addWidget(bar)
        row = QtGui.QHBoxLayout()
        row.setContentsMargins(0, 0, 0, 0)
        self.labels = []
        for name, align in (("legendMin", QtCore.Qt.AlignLeft), ("legendZero", QtCore.Qt.AlignHCenter),
                            ("legendMax", QtCore.Qt.AlignRight)):
            label = QtGui.QLabel("")
            label.setObjectName(name)
            label.setAlignment(align)
            row.addWidget(label, 1)
            self.labels.append(label)
        wrap = QtGui.QWidget()
        wrap.setFixedWidth(SIZE[0])
        wrap.setLayout(row)
        v.addWidget(wrap)
        self.beyond = QtGui.QLabel("")
        self.beyond.setObjectName("legendBeyond")
        self.beyond.setWordWrap(True)
        v.addWidget(self.beyond)
        red = QtGui.QLabel("red crosses: holder/shank collision with the stock")
        red.setStyleSheet("QLabel { color: #c00000; }")
        v.addWidget(red)
        grey = QtGui.QLabel("grey: no design under the cell")
        grey.setStyleSheet(f"QLabel {{ background: {NO_DESIGN_HEX}; color: white; padding: 1px 4px; }}")
        v.addWidget(grey)

    def clear(self) -> None:
        for label in self.labels + [self.beyond]:
            label.setText("")
            label.setProperty("value", None)

    def show(self, deviation: np.ndarray, band: float, along: str) -> None:
        """The band's ends and the extremes beyond it of `deviation` (mm, measured `along`: 'the normal' or
        'vertical'); each label's number in its 'value' property."""
        self.title.setText(f"Colours of the stock in the 3D view: deviation {along}, mm")
        for label, value in zip(self.labels, (-band, 0.0, band)):
            label.setText("0" if value == 0 else signed(value) + (" mm" if value > 0 else ""))
            label.setProperty("value", value)
        above, below, high, low = beyond_band(deviation, band)
        parts = ([f"{above} cells above, up to {signed(high)} mm (darkest red)"] if above else []) \
            + ([f"{below} cells below, down to {signed(low)} mm (darkest blue)"] if below else [])
        self.beyond.setText("beyond the band: " + "; ".join(parts) if parts
                            else f"all within the band (extremes {signed(low)} / {signed(high)} mm)")
        self.beyond.setProperty("value", [above, below, high, low])

