# `cpack -G DEB` in the build folder: vrflow_<version>_<arch>.deb, the install tree under /usr,
# its Depends computed by dpkg-shlibdeps (Debian: dpkg-dev) from what the programs, libraries and
# module executables link, so that `apt install ./vrflow_*.deb` brings in the rest.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME vrflow)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "vrflow")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Data-flow runtime for interactive simulations: modules, filters, daemons, launcher")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "vrflow developers <vrflow@localhost>")
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# dpkg-shlibdeps resolves the package's own libraries (libvrflow_*.so.0) from the staging tree.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS ${PROJECT_BINARY_DIR}/lib)
# A shlibs file and the ldconfig trigger, for the shared libraries in /usr/lib.
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
# `vrflow launch` starts daemons over ssh; the fluid's MPI blocks run under mpirun.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "openssh-client, openmpi-bin")
# What building a module or filter plugin against the installed SDK uses, and the manifest check.
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "g++, cmake, pkg-config, libxml2-utils")
include(CPack)
