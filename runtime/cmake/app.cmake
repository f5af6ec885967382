# vrflow::app (libvrflow_app.so) — the application model: load, validate and save application
# files, read node package manifests. Used by the daemon, the supervisor, the launcher and the
# editor; never by a module.
vrflow_add_library(app SHARED
  PRIVATE_INCLUDE ${CMAKE_CURRENT_SOURCE_DIR}/src/app
  SOURCES
    src/app/application_reader.cpp
    src/app/editor_reader.cpp
    src/app/application_writer.cpp
    src/app/catalog.cpp
    src/app/composite.cpp
    src/app/composite_reader.cpp
    src/app/composite_writer.cpp
    src/app/diagnostic.cpp
    src/app/element_reader.cpp
    src/app/expand.cpp
    src/app/expand_body.cpp
    src/app/file_io.cpp
    src/app/graph.cpp
    src/app/rates.cpp
    src/app/manifest_reader.cpp
    src/app/model.cpp
    src/app/mpi_job.cpp
    src/app/overrides.cpp
    src/app/package.cpp
    src/app/package_files.cpp
    src/app/source_location.cpp
    src/app/source_text.cpp
    src/app/template_text.cpp
    src/app/text_util.cpp
    src/app/validate.cpp
    src/app/validate_connections.cpp
    src/app/validate_cycles.cpp
    src/app/validate_mpi_jobs.cpp
    src/app/xml_out.cpp
  PUBLIC_DEPS vrflow::module
  PRIVATE_DEPS pugixml::pugixml)
