/* stand-in for OSQP's osqp.h: the float type AMD's Control and Info use */
#ifndef OSQP_H
#define OSQP_H
typedef double OSQPFloat;
#endif
