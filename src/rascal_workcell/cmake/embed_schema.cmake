# Writes the schema YAML into a C++ source as one raw string (run by add_custom_command).
file(READ ${IN} TEXT)
file(WRITE ${OUT} "// Generated from schema/parameters.yaml; edit that file.\n"
  "namespace rascal_workcell { extern const char* const kSchemaText;\n"
  "const char* const kSchemaText = R\"RASCAL_SCHEMA(${TEXT})RASCAL_SCHEMA\"; }\n")
