# cmake -DINPUT=file.cl -DOUTPUT=file_cl.cpp -DNAME=file -P EmbedFile.cmake
file(READ ${INPUT} hex HEX)
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
file(WRITE ${OUTPUT} "// Generated from ${INPUT}; do not edit.\nnamespace vb::kernels {\nextern const char kernel_${NAME}_cl[] = {${bytes} 0x00};\n}\n")
