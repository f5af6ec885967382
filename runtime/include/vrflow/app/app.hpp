#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

/// The application model library in one include: model, load, save, catalog, validation.
#include "vrflow/app/catalog.hpp"         // IWYU pragma: export
#include "vrflow/app/composite.hpp"       // IWYU pragma: export
#include "vrflow/app/composite_file.hpp"  // IWYU pragma: export
#include "vrflow/app/diagnostic.hpp"      // IWYU pragma: export
#include "vrflow/app/expand.hpp"          // IWYU pragma: export
#include "vrflow/app/graph.hpp"           // IWYU pragma: export
#include "vrflow/app/loader.hpp"          // IWYU pragma: export
#include "vrflow/app/model.hpp"           // IWYU pragma: export
#include "vrflow/app/mpi_job.hpp"         // IWYU pragma: export
#include "vrflow/app/package.hpp"         // IWYU pragma: export
#include "vrflow/app/package_files.hpp"   // IWYU pragma: export
#include "vrflow/app/validate.hpp"        // IWYU pragma: export
#include "vrflow/app/writer.hpp"          // IWYU pragma: export
