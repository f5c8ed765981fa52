# catkin_simple's macros: a package's CMakeLists.txt names its targets, and the dependencies,
# include folder, messages and exports come from its package.xml and its folders.
#
#   catkin_simple([ALL_DEPS_REQUIRED])
#   cs_add_library(target sources... [NO_AUTO_LINK] [NO_AUTO_DEP] [NO_AUTO_EXPORT])
#   cs_add_executable(target sources... [NO_AUTO_LINK] [NO_AUTO_DEP])
#   cs_install([more targets...])
#   cs_install_scripts(scripts...)
#   cs_export([INCLUDE_DIRS ...] [LIBRARIES ...] [CATKIN_DEPENDS ...] [DEPENDS ...] [CFG_EXTRAS ...])

if(_CS_MACROS_DEFINED)
  return()
endif()
set(_CS_MACROS_DEFINED TRUE)

include(CMakeParseArguments)

# Sets `out` to TRUE when catkin package `dep` has messages: its <dep>-msg-paths.cmake is where
# generate_messages() looks for it (share/<dep>/cmake under this devel space and the
# workspaces), which on Debian is not always beside the package's CMake config.
function(_cs_has_messages dep out)
  set(workspaces ${CATKIN_DEVEL_PREFIX} ${CATKIN_WORKSPACES})
  unset(_cs_msg_paths CACHE)
  find_file(_cs_msg_paths share/${dep}/cmake/${dep}-msg-paths.cmake PATHS ${workspaces})
  if(_cs_msg_paths)
    set(${out} TRUE PARENT_SCOPE)
  else()
    set(${out} FALSE PARENT_SCOPE)
  endif()
  unset(_cs_msg_paths CACHE)
endfunction()

# Adds the package's files in folder `kind` (msg, srv, action) to its message generation; sets
# `found` to TRUE when there were any.
macro(_cs_add_interface_folder kind found)
  if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${kind})
    if(${kind} STREQUAL "msg")
      add_message_files(DIRECTORY msg)
    elseif(${kind} STREQUAL "srv")
      add_service_files(DIRECTORY srv)
    else()
      add_action_files(DIRECTORY action)
    endif()
    set(${found} TRUE)
  endif()
endmacro()

macro(catkin_simple)
  cmake_parse_arguments(_cs "ALL_DEPS_REQUIRED" "" "" ${ARGN})

  # The package's own targets, made by cs_add_*; a target of this name builds them all.
  add_custom_target(${PROJECT_NAME}_package)
  set(${PROJECT_NAME}_TARGETS)
  set(${PROJECT_NAME}_LIBRARIES)

  find_package(catkin REQUIRED)
  if(NOT _CATKIN_CURRENT_PACKAGE)
    catkin_package_xml()
  endif()

  # The build dependencies that are catkin packages; the others (system libraries) are the
  # package's own to find.
  set(${PROJECT_NAME}_CATKIN_BUILD_DEPENDS)
  foreach(_cs_dep ${${PROJECT_NAME}_BUILD_DEPENDS})
    if(_cs_ALL_DEPS_REQUIRED)
      find_package(${_cs_dep} REQUIRED)
    else()
      find_package(${_cs_dep} QUIET)
    endif()
    if(${_cs_dep}_FOUND_CATKIN_PROJECT)
      list(APPEND ${PROJECT_NAME}_CATKIN_BUILD_DEPENDS ${_cs_dep})
    endif()
  endforeach()
  find_package(catkin REQUIRED COMPONENTS ${${PROJECT_NAME}_CATKIN_BUILD_DEPENDS})

  set(${PROJECT_NAME}_LOCAL_INCLUDE_DIR)
  if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include)
    set(${PROJECT_NAME}_LOCAL_INCLUDE_DIR ${CMAKE_CURRENT_SOURCE_DIR}/include)
  endif()
  include_directories(${${PROJECT_NAME}_LOCAL_INCLUDE_DIR} ${catkin_INCLUDE_DIRS})

  # What the package's targets wait for: the dependencies' generated code and, below, its own.
  set(${PROJECT_NAME}_CS_TARGET_DEPENDS ${catkin_EXPORTED_TARGETS})

  if(message_generation_FOUND_CATKIN_PROJECT)
    # An action's messages are made of actionlib_msgs' (GoalID, GoalStatus), whose CMake also
    # defines add_action_files: a package with actions depends on it whether its package.xml
    # names actionlib_msgs or only actionlib.
    set(_cs_has_actions FALSE)
    if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/action)
      set(_cs_has_actions TRUE)
      find_package(actionlib_msgs REQUIRED)
    endif()
    set(_cs_interfaces FALSE)
    _cs_add_interface_folder(msg _cs_interfaces)
    _cs_add_interface_folder(srv _cs_interfaces)
    _cs_add_interface_folder(action _cs_interfaces)
    if(_cs_interfaces)
      set(_cs_msg_depends)
      foreach(_cs_dep ${${PROJECT_NAME}_CATKIN_BUILD_DEPENDS})
        _cs_has_messages(${_cs_dep} _cs_dep_has_messages)
        if(_cs_dep_has_messages)
          list(APPEND _cs_msg_depends ${_cs_dep})
        endif()
      endforeach()
      if(_cs_has_actions)
        list(FIND _cs_msg_depends actionlib_msgs _cs_index)
        if(_cs_index EQUAL -1)
          list(APPEND _cs_msg_depends actionlib_msgs)
        endif()
      endif()
      generate_messages(DEPENDENCIES ${_cs_msg_depends})
      list(APPEND ${PROJECT_NAME}_CS_TARGET_DEPENDS ${${PROJECT_NAME}_EXPORTED_TARGETS})
    endif()
  endif()

  if(dynamic_reconfigure_FOUND_CATKIN_PROJECT)
    file(GLOB _cs_cfg_files RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR}/cfg/*.cfg)
    if(_cs_cfg_files)
      generate_dynamic_reconfigure_options(${_cs_cfg_files})
      list(APPEND ${PROJECT_NAME}_CS_TARGET_DEPENDS ${PROJECT_NAME}_gencfg)
    endif()
  endif()
endmacro()

# A target made by cs_add_*: linked to the catkin dependencies' libraries, built after their
# generated code and the package's own, and counted among the package's targets.
macro(_cs_adopt_target target no_link no_dep)
  if(NOT ${no_link})
    target_link_libraries(${target} ${catkin_LIBRARIES})
  endif()
  if(NOT ${no_dep} AND ${PROJECT_NAME}_CS_TARGET_DEPENDS)
    add_dependencies(${target} ${${PROJECT_NAME}_CS_TARGET_DEPENDS})
  endif()
  add_dependencies(${PROJECT_NAME}_package ${target})
  list(APPEND ${PROJECT_NAME}_TARGETS ${target})
endmacro()

macro(cs_add_executable target)
  cmake_parse_arguments(_cs_exe "NO_AUTO_LINK;NO_AUTO_DEP" "" "" ${ARGN})
  add_executable(${target} ${_cs_exe_UNPARSED_ARGUMENTS})
  _cs_adopt_target(${target} _cs_exe_NO_AUTO_LINK _cs_exe_NO_AUTO_DEP)
endmacro()

macro(cs_add_library target)
  cmake_parse_arguments(_cs_lib "NO_AUTO_LINK;NO_AUTO_DEP;NO_AUTO_EXPORT" "" "" ${ARGN})
  add_library(${target} ${_cs_lib_UNPARSED_ARGUMENTS})
  _cs_adopt_target(${target} _cs_lib_NO_AUTO_LINK _cs_lib_NO_AUTO_DEP)
  if(NOT _cs_lib_NO_AUTO_EXPORT)
    list(APPEND ${PROJECT_NAME}_LIBRARIES ${target})
  endif()
endmacro()

# Installs the package's cs_ targets and any others named, its include folder and the folders
# of shared content it has (launch files, robots, worlds, ...).
macro(cs_install)
  install(TARGETS ${${PROJECT_NAME}_TARGETS} ${ARGN}
    ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
    LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
    RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
  if(${PROJECT_NAME}_LOCAL_INCLUDE_DIR)
    install(DIRECTORY ${${PROJECT_NAME}_LOCAL_INCLUDE_DIR}/
      DESTINATION ${CATKIN_GLOBAL_INCLUDE_DESTINATION}
      FILES_MATCHING PATTERN "*.h" PATTERN "*.hpp")
  endif()
  foreach(_cs_folder launch rviz urdf meshes maps worlds Media param)
    if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${_cs_folder})
      install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${_cs_folder}/
        DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/${_cs_folder})
    endif()
  endforeach()
endmacro()

macro(cs_install_scripts)
  install(PROGRAMS ${ARGN} DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endmacro()

# catkin_package() with the package's include folder, its cs_ libraries and its run dependencies
# that are catkin packages, plus whatever is passed.
macro(cs_export)
  cmake_parse_arguments(_cs_export "" "" "INCLUDE_DIRS;LIBRARIES;CATKIN_DEPENDS;DEPENDS;CFG_EXTRAS"
    ${ARGN})
  set(${PROJECT_NAME}_CATKIN_RUN_DEPENDS)
  foreach(_cs_dep ${${PROJECT_NAME}_RUN_DEPENDS})
    find_package(${_cs_dep} QUIET)
    if(${_cs_dep}_FOUND_CATKIN_PROJECT)
      list(APPEND ${PROJECT_NAME}_CATKIN_RUN_DEPENDS ${_cs_dep})
    endif()
  endforeach()
  catkin_package(
    INCLUDE_DIRS ${${PROJECT_NAME}_LOCAL_INCLUDE_DIR} ${_cs_export_INCLUDE_DIRS}
    LIBRARIES ${${PROJECT_NAME}_LIBRARIES} ${_cs_export_LIBRARIES}
    CATKIN_DEPENDS ${${PROJECT_NAME}_CATKIN_RUN_DEPENDS} ${_cs_export_CATKIN_DEPENDS}
    DEPENDS ${_cs_export_DEPENDS}
    CFG_EXTRAS ${_cs_export_CFG_EXTRAS})
endmacro()
