"""Reports: the validate stages, their text and HTML, figures."""
