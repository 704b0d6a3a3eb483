/* fmi2TypesPlatform.h: the platform types of the FMI 2.0 interface, written for stackbeam
   from the text of the standard ("Functional Mock-up Interface for Model Exchange and
   Co-Simulation", version 2.0, section 2.1.2 "Platform Dependent Definitions"), the
   "default" platform. Names and types as the standard gives them. */
#ifndef fmi2TypesPlatform_h
#define fmi2TypesPlatform_h

/* Platform (unique identification of this header file) */
#define fmi2TypesPlatform "default"

typedef void*           fmi2Component;            /* pointer to an FMU instance */
typedef void*           fmi2ComponentEnvironment; /* pointer to the importer's environment */
typedef void*           fmi2FMUstate;             /* pointer to an internal FMU state */
typedef unsigned int    fmi2ValueReference;
typedef double          fmi2Real;
typedef int             fmi2Integer;
typedef int             fmi2Boolean;
typedef char            fmi2Char;
typedef const fmi2Char* fmi2String;
typedef char            fmi2Byte;

#define fmi2True  1
#define fmi2False 0

#endif /* fmi2TypesPlatform_h */
