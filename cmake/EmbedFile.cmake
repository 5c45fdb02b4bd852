# cmake -DINPUT=file.cl -DOUTPUT=file_cl.cpp -DNAME=file -P EmbedFile.cmake
# Bytes as unsigned char (sources may hold UTF-8 in comments), exposed as a NUL-terminated char*.
file(READ ${INPUT} hex HEX)
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
file(WRITE ${OUTPUT} "// Generated from ${INPUT}; do not edit.\nnamespace vb::kernels {\nstatic const unsigned char bytes_${NAME}[] = {${bytes} 0x00};\nextern const char* const kernel_${NAME}_cl = reinterpret_cast<const char*>(bytes_${NAME});\n}\n")
