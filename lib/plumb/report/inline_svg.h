// plumb/report/inline_svg.h — gnuplot's SVG files put inside a page, so that the page needs no
// file beside it and makes no request (issue 13 point 10).
//
// A file of gnuplot's svg terminal is a document: an XML prolog, sometimes a DOCTYPE and
// comments, then one <svg> element whose <defs> name its point symbols and filters with
// fixed ids (gpPt0, gpDot, textbox, gnuplot_canvas, ...) that the drawing refers to
// (xlink:href='#gpPt7', filter='url(#textbox)'). Several such elements in one HTML page would
// share those ids, and a reference would resolve to the first figure's definition. InlineSvg
// keeps the <svg> element only and gives each id a prefix of its own, rewriting the
// references to it (href="#id", xlink:href='#id', url(#id)); gnuplot's <title>Gnuplot</title>
// is dropped (a browser would show it as the figure's tooltip).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace plumb::report {

/// The <svg> element of `document` for an HTML page: what precedes it dropped, every id
/// prefixed by `id_prefix` (letters, digits, '-' or '_'; may be empty) and the references to
/// those ids rewritten. Throws plumb::Error naming `name` when there is no <svg ...> ... </svg>
/// element or the prefix has other characters.
std::string InlineSvg(std::string_view document, const std::string& id_prefix,
                      const std::string& name = "SVG");

/// One SVG file as markup for the page.
struct InlineFigure {
  std::string file;  ///< its name in the folder, e.g. "series.svg"
  std::string svg;   ///< InlineSvg of its content, ids prefixed by "<stem>-"
};

/// Reads the SVG files `names` (relative to `folder`, as RunGnuplot's `written` lists them),
/// makes them inline markup in that order, and removes the files: the page holds them.
/// Throws plumb::Error naming the file when one cannot be read or is not an SVG document.
std::vector<InlineFigure> TakeSvgFiles(const std::string& folder,
                                       const std::vector<std::string>& names);

}  // namespace plumb::report
