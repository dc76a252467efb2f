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
find_package(VTK 9.1 REQUIRED COMPONENTS
  CommonCore CommonDataModel CommonColor IOXML IOParallelXML IOImage
  FiltersCore FiltersSources FiltersGeneral FiltersExtraction
  RenderingCore RenderingOpenGL2 RenderingFreeType RenderingAnnotation InteractionStyle
  ChartsCore ViewsContext2D RenderingContext2D RenderingContextOpenGL2)

if(BASALT_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()

# HDF5 as one imported target, private to the I/O layer and tools.
add_library(basalt_hdf5 INTERFACE)
target_include_directories(basalt_hdf5 SYSTEM INTERFACE ${HDF5_C_INCLUDE_DIRS} ${HDF5_INCLUDE_DIRS})
target_link_libraries(basalt_hdf5 INTERFACE ${HDF5_C_LIBRARIES} ${HDF5_LIBRARIES} MPI::MPI_C)
target_compile_definitions(basalt_hdf5 INTERFACE ${HDF5_DEFINITIONS} ${HDF5_C_DEFINITIONS})
add_library(basalt::hdf5 ALIAS basalt_hdf5)
