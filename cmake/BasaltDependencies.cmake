# All third-party dependencies come from Debian 12 packages (scripts/install-deps.sh).
find_package(MPI REQUIRED COMPONENTS C CXX)

# The parallel HDF5 build (libhdf5-openmpi-dev); C only: parallel HDF5 has no C++ API.
set(HDF5_PREFER_PARALLEL ON)
find_package(HDF5 REQUIRED COMPONENTS C)
if(NOT HDF5_IS_PARALLEL)
  message(FATAL_ERROR "Basalt needs the parallel HDF5 build (apt-get install libhdf5-openmpi-dev)")
endif()

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
set(CGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE TRUE)
find_package(CGAL REQUIRED)
find_package(tomlplusplus REQUIRED)
find_package(CLI11 REQUIRED)
find_package(fmt REQUIRED)
# VTK is optional (BASALT_WITH_VTK, CMakeLists.txt): without it there are no VTK frames, no pictures (in situ
# or basalt-view's), and basalt-view only says why; packing, runs, checkpoints, XDMF and field series stay.
# Debian 12's python3-paraview conflicts with libvtk9-dev's python3-vtk9, so a machine with ParaView's
# Python module has no VTK development files (scripts/install-deps.sh, docs/reliability.md).
set(BASALT_VTK_COMPONENTS
  CommonCore CommonDataModel CommonColor IOXML IOParallelXML IOImage
  FiltersCore FiltersSources FiltersGeneral FiltersExtraction
  RenderingCore RenderingOpenGL2 RenderingFreeType RenderingAnnotation InteractionStyle
  ChartsCore ViewsContext2D RenderingContext2D RenderingContextOpenGL2)
set(BASALT_WITHOUT_VTK_REASON "")
if(BASALT_WITH_VTK)
  find_package(VTK 9.1 QUIET COMPONENTS ${BASALT_VTK_COMPONENTS})
  if(NOT VTK_FOUND)
    # A normal variable shadows the cache's ON for this configuration only: once VTK is installed, the
    # next configuration finds it without being told.
    set(BASALT_WITH_VTK OFF)
    set(BASALT_WITHOUT_VTK_REASON "VTK 9.1's development files (libvtk9-dev) were not found when configured")
    message(WARNING
      "Basalt: VTK 9.1's development files (Debian: libvtk9-dev) were not found: building without VTK "
      "(BASALT_WITH_VTK=OFF). basalt-pack, basalt-run, checkpoints, XDMF (open ckpt_series.xmf in ParaView) "
      "and field series work; VTK frames (--frames-every), in-situ pictures (--render-every) and basalt-view's "
      "commands (render, movie, plot, convert, info) are left out. Install libvtk9-dev and configure again to "
      "have them. "
      "${VTK_NOT_FOUND_MESSAGE}")
  endif()
else()
  set(BASALT_WITHOUT_VTK_REASON "configured with -DBASALT_WITH_VTK=OFF")
  message(STATUS
    "Basalt: BASALT_WITH_VTK=OFF: nothing links or includes VTK; no VTK frames (--frames-every), in-situ "
    "pictures (--render-every) or basalt-view commands (render, movie, plot, convert, info); checkpoints, XDMF "
    "and field series as always")
endif()
if(BASALT_WITH_VTK)
  message(STATUS "Basalt: with VTK ${VTK_VERSION} (BASALT_WITH_VTK=ON)")
endif()
# What this configuration chose, for scripts that read the cache (scripts/demo.sh).
set(BASALT_HAS_VTK ${BASALT_WITH_VTK} CACHE INTERNAL "VTK is used by this build (BASALT_WITH_VTK, found)")

# Python (optional, BASALT_WITH_PYTHON): Debian's interpreter /usr/bin/python3, whose packages (numpy, h5py,
# pytest) the package and its tests use, unless -DPython3_EXECUTABLE names another; pybind11 from pybind11-dev.
# A pyenv python3 earlier on PATH has other packages (docs/python.md).
set(BASALT_WITHOUT_PYTHON_REASON "configured with -DBASALT_WITH_PYTHON=OFF")
if(BASALT_WITH_PYTHON AND BASALT_SANITIZE)
  # An instrumented module cannot be loaded into Debian's uninstrumented python3 (the sanitizer's runtime must
  # come first), so its tests could only fail there.
  set(BASALT_WITH_PYTHON OFF)
  set(BASALT_WITHOUT_PYTHON_REASON "a sanitizer build (BASALT_SANITIZE=${BASALT_SANITIZE}): python3 cannot load an instrumented module")
  message(STATUS "Basalt: no Python package (BASALT_WITH_PYTHON=OFF): ${BASALT_WITHOUT_PYTHON_REASON}")
elseif(BASALT_WITH_PYTHON)
  if(NOT Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
    set(Python3_EXECUTABLE /usr/bin/python3)
  endif()
  find_package(Python3 QUIET COMPONENTS Interpreter Development.Module)
  if(Python3_FOUND)
    # pybind11's config uses FindPython's targets once Python3 is found (its "new" mode).
    find_package(pybind11 2.6 CONFIG QUIET)
  endif()
  if(NOT Python3_FOUND OR NOT pybind11_FOUND)
    set(BASALT_WITH_PYTHON OFF)
    if(NOT Python3_FOUND)
      set(BASALT_WITHOUT_PYTHON_REASON "Python 3's development files (python3-dev) were not found")
    else()
      set(BASALT_WITHOUT_PYTHON_REASON "pybind11 (pybind11-dev) was not found")
    endif()
    message(STATUS "Basalt: no Python package (BASALT_WITH_PYTHON=OFF): ${BASALT_WITHOUT_PYTHON_REASON}; "
                   "install pybind11-dev and python3-dev (scripts/install-deps.sh) and configure again")
  else()
    message(STATUS "Basalt: Python package for ${Python3_EXECUTABLE} ${Python3_VERSION}, pybind11 ${pybind11_VERSION}")
  endif()
elseif(NOT BASALT_SANITIZE)
  message(STATUS "Basalt: BASALT_WITH_PYTHON=OFF: no Python package")
endif()
set(BASALT_HAS_PYTHON ${BASALT_WITH_PYTHON} CACHE INTERNAL "The Python package is built (BASALT_WITH_PYTHON, found)")

if(BASALT_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()

# HDF5 as one imported target, private to the I/O layer and tools.
add_library(basalt_hdf5 INTERFACE)
target_include_directories(basalt_hdf5 SYSTEM INTERFACE ${HDF5_C_INCLUDE_DIRS} ${HDF5_INCLUDE_DIRS})
target_link_libraries(basalt_hdf5 INTERFACE ${HDF5_C_LIBRARIES} ${HDF5_LIBRARIES} MPI::MPI_C)
target_compile_definitions(basalt_hdf5 INTERFACE ${HDF5_DEFINITIONS} ${HDF5_C_DEFINITIONS})
add_library(basalt::hdf5 ALIAS basalt_hdf5)
