# Orocos KDL as the imported target kincal::orocos_kdl, made from what find_package(orocos_kdl) found
# on this machine. Debian's orocos_kdl config defines no target, only orocos_kdl_LIBRARIES (the bare
# name orocos-kdl) and orocos_kdl_INCLUDE_DIRS; linked raw they would be written into kincal's export
# as they are. So kincal's targets link this one, and kincalConfig.cmake includes this file again at
# the consumer's configure time, after its find_dependency(orocos_kdl). Nothing is created when the
# library or its headers are not found: the includer says so.
if(NOT TARGET kincal::orocos_kdl)
  if(TARGET orocos-kdl)
    # upstream's config exports the target orocos-kdl
    add_library(kincal::orocos_kdl INTERFACE IMPORTED)
    target_link_libraries(kincal::orocos_kdl INTERFACE orocos-kdl)
  else()
    # orocos_kdl_DIR is <libdir>/cmake/orocos_kdl, with <libdir> lib or lib/<multiarch>
    find_library(KINCAL_OROCOS_KDL_LIBRARY NAMES orocos-kdl HINTS "${orocos_kdl_DIR}/../..")
    find_path(KINCAL_OROCOS_KDL_INCLUDE_DIR kdl/frames.hpp
      HINTS "${orocos_kdl_DIR}/../../../include" "${orocos_kdl_DIR}/../../../../include")
    mark_as_advanced(KINCAL_OROCOS_KDL_LIBRARY KINCAL_OROCOS_KDL_INCLUDE_DIR)
    if(KINCAL_OROCOS_KDL_LIBRARY AND KINCAL_OROCOS_KDL_INCLUDE_DIR)
      add_library(kincal::orocos_kdl INTERFACE IMPORTED)
      target_include_directories(kincal::orocos_kdl INTERFACE ${KINCAL_OROCOS_KDL_INCLUDE_DIR} ${orocos_kdl_INCLUDE_DIRS})
      # KDL's headers include Eigen's
      target_link_libraries(kincal::orocos_kdl INTERFACE ${KINCAL_OROCOS_KDL_LIBRARY} Eigen3::Eigen)
    endif()
  endif()
endif()
