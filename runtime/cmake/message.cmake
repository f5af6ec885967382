# The binary message layout (docs/message-layout.md): builder, checked zero-copy reader, object
# types, ids and digests; part of vrflow::module (cmake/module.cmake). Eigen (header-only) does the
# shape geometry; it stays private: the node packages that include vrflow/message/eigen.hpp (Eigen
# views of the wire's arrays) link Eigen3::Eigen themselves, and nothing else sees it.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
set(vrflow_message_sources
    src/message/builder.cpp
    src/message/builtin_types.cpp
    src/message/shape.cpp
    src/message/byte_sink.cpp
    src/message/chunk_views.cpp
    src/message/digest.cpp
    src/message/empty_message.cpp
    src/message/ids.cpp
    src/message/input_events.cpp
    src/message/object_type.cpp
    src/message/object_writer.cpp
    src/message/parse.cpp
    src/message/stamps.cpp
    src/message/view.cpp)
