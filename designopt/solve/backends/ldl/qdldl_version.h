#define QDLDL_VERSION "0.1.8"
