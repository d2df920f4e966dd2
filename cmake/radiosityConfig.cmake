# find_package(radiosity) gives two imported targets:
#
#   radiosity::radiosity         the shared library; needs nothing else
#   radiosity::radiosity_static  the static library; its dependencies (Embree 3,
#                                OpenMP, assimp, cJSON, cairo; LAPACKE and OpenBLAS are
#                                opened at run time by the direct solver) are
#                                found here, so their development files must be
#                                installed (on Debian: scripts/setup.sh's list)
include(CMakeFindDependencyMacro)
find_dependency(embree 3)
find_dependency(OpenMP COMPONENTS C)
find_dependency(PkgConfig)
foreach(rad_dependency ASSIMP=assimp CJSON=libcjson CAIRO=cairo)
  string(REPLACE "=" ";" rad_dependency "${rad_dependency}")
  list(GET rad_dependency 0 rad_prefix)
  list(GET rad_dependency 1 rad_module)
  if(NOT TARGET PkgConfig::${rad_prefix})
    pkg_check_modules(${rad_prefix} QUIET IMPORTED_TARGET ${rad_module})
    if(NOT ${rad_prefix}_FOUND)
      set(radiosity_FOUND FALSE)
      set(radiosity_NOT_FOUND_MESSAGE "radiosity needs pkg-config module '${rad_module}'")
      return()
    endif()
  endif()
endforeach()
include("${CMAKE_CURRENT_LIST_DIR}/radiosityTargets.cmake")
