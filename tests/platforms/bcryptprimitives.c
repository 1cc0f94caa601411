/* tests/platforms/bcryptprimitives.c: a stand-in for Windows' bcryptprimitives.dll, for wine only.
 *
 * Rust's standard library (1.78 and newer) draws its random seeds from ProcessPrng in
 * bcryptprimitives.dll, a system DLL of Windows 10 and newer (Rust's minimum for the
 * x86_64-pc-windows-gnu target). Wine 8.0 (Debian 12) has no such DLL, so LoadLibrary of the FMU's
 * DLL fails there with error 126. tests/platforms.sh builds this file next to the harness
 * (the executable's folder is searched first); the FMU's DLL itself ships without it. */
#include <windows.h>
#include <ntsecapi.h>

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length) {
    while (length > 0) {
        ULONG chunk = length > 0x10000000 ? 0x10000000 : (ULONG)length;
        if (!RtlGenRandom(data, chunk)) return FALSE;
        data += chunk;
        length -= chunk;
    }
    return TRUE;
}
