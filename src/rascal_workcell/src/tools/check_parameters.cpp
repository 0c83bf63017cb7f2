// check_parameters FILE READER...: reads every key the schema lists for each reader with the C++
// Parameters and the Workcell, as the nodes do; prints the first error in one line and exits 1.
// Tests run it beside the Python validator: a value one accepts the other must accept too.
#include <iostream>

#include "rascal_workcell/Workcell.hpp"

using rascal_workcell::ParameterSchema;
using rascal_workcell::Parameters;

namespace {
void readAll(const Parameters& p) {
  rascal_workcell::Workcell::fromParameters(p);  // the stations, as every node reads them
  for (const auto& s : ParameterSchema::builtin().specs()) {
    if (!s.readBy(p.reader()) || s.key.rfind("stations", 0) == 0) continue;
    if (s.type == "map") {
      for (const auto& name : p.names(s.key)) p.vector(s.key + "." + name);
    } else if (s.key.find('*') != std::string::npos) {
      continue;  // read with its map
    } else if (s.type == "number" || s.type == "integer") {
      p.number(s.key);
    } else if (s.type == "bool") {
      p.flag(s.key);
    } else if (s.type == "string" || s.type == "enum") {
      p.text(s.key);
    } else if (s.type == "vector") {
      p.vector(s.key);
    } else if (s.type == "vector_list") {
      p.vectors(s.key);
    }
  }
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: check_parameters CONFIG.yaml READER [READER...]\n";
    return 2;
  }
  try {
    for (int i = 2; i < argc; ++i) readAll(Parameters::fromFile(argv[1], argv[i]));
  } catch (const rascal_workcell::ParameterError& e) {
    std::cout << e.what() << "\n";
    return 1;
  }
  std::cout << "ok\n";
  return 0;
}
