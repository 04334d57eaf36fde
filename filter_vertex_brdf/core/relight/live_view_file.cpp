// The live view as a text file (live_view_file.h).
#include "relight/live_view_file.h"

#include <fstream>
#include <iomanip>
#include <sstream>

#include "base/errors.h"

namespace vbrdf {

void write_live_view(const std::string &path, const LiveViewRecord &r) {
  std::ostringstream s;
  s << std::setprecision(17) << "vbrdf_live_view 1\nviewport";
  for (int v : r.viewport) s << ' ' << v;
  s << "\nmodelview";
  for (double m : r.view.modelview) s << ' ' << m;
  s << "\nprojection";
  for (double m : r.view.projection) s << ' ' << m;
  s << "\nlight";
  for (float l : r.view.light_eye) s << ' ' << l;
  s << "\ndisplay " << int(r.view.display) << "\nexposure " << r.view.exposure << "\n";
  std::ofstream f(path, std::ios::trunc);
  f << s.str();
  if (!f.good()) throw ProcessingError("Live relighting: cannot write the view log " + path + ".");
}

LiveViewRecord read_live_view(const std::string &path) {
  std::ifstream f(path);
  if (!f) throw InputError("Cannot read the live view file " + path + ".");
  LiveViewRecord r;
  std::string line, key;
  int line_no = 0;
  bool header = false;
  while (std::getline(f, line)) {
    ++line_no;
    std::istringstream in(line);
    if (!(in >> key)) continue;
    bool ok = true;
    if (key == "vbrdf_live_view") header = true;
    else if (key == "viewport") for (int &v : r.viewport) ok = ok && bool(in >> v);
    else if (key == "modelview") for (double &m : r.view.modelview) ok = ok && bool(in >> m);
    else if (key == "projection") for (double &m : r.view.projection) ok = ok && bool(in >> m);
    else if (key == "light") for (float &l : r.view.light_eye) ok = ok && bool(in >> l);
    else if (key == "display") {
      int d = 0;
      ok = bool(in >> d) && d >= 0 && d <= 5;
      r.view.display = LiveDisplay(d);
    } else if (key == "exposure") ok = bool(in >> r.view.exposure);
    else ok = false;
    if (!ok) throw InputError("Live view file " + path + ", line " + std::to_string(line_no) + ": cannot read '" + line + "'.");
  }
  if (!header) throw InputError("Live view file " + path + " does not start with 'vbrdf_live_view 1'.");
  return r;
}

} // namespace vbrdf
