
var createGeomipCore = (() => {
  var _scriptDir = import.meta.url;
  
  return (
function(createGeomipCore) {
  createGeomipCore = createGeomipCore || {};

  var Module = typeof createGeomipCore != 'undefined' ? createGeomipCore : {};
  var readyPromiseResolve, readyPromiseReject;
  Module['ready'] = new Promise(function(resolve, reject) {
    readyPromiseResolve = resolve;
    readyPromiseReject = reject
  });
  var moduleOverrides = Object.assign({}, Module);
  var arguments_ = [];
  var thisProgram = './this.program';
  var quit_ = (status, toThrow) => {
    throw toThrow
  };
  var ENVIRONMENT_IS_WEB = typeof window == 'object';
  var ENVIRONMENT_IS_WORKER = typeof importScripts == 'function';
  var ENVIRONMENT_IS_NODE = typeof process == 'object' && typeof process.versions == 'object' &&
      typeof process.versions.node == 'string';
  var scriptDirectory = '';
  function locateFile(path) {
    if (Module['locateFile']) {
      return Module['locateFile'](path, scriptDirectory)
    }
    return scriptDirectory + path
  }
  var read_, readAsync, readBinary, setWindowTitle;
  if (ENVIRONMENT_IS_WEB || ENVIRONMENT_IS_WORKER) {
    if (ENVIRONMENT_IS_WORKER) {
      scriptDirectory = self.location.href
    } else if (typeof document != 'undefined' && document.currentScript) {
      scriptDirectory = document.currentScript.src
    }
    if (_scriptDir) {
      scriptDirectory = _scriptDir
    }
    if (scriptDirectory.indexOf('blob:') !== 0) {
      scriptDirectory = scriptDirectory.substr(0, scriptDirectory.replace(/[?#].*/, '').lastIndexOf('/') + 1)
    } else {
      scriptDirectory = ''
    }
    {
      read_ = (url => {
        var xhr = new XMLHttpRequest;
        xhr.open('GET', url, false);
        xhr.send(null);
        return xhr.responseText
      });
      if (ENVIRONMENT_IS_WORKER) {
        readBinary = (url => {
          var xhr = new XMLHttpRequest;
          xhr.open('GET', url, false);
          xhr.responseType = 'arraybuffer';
          xhr.send(null);
          return new Uint8Array(xhr.response)
        })
      }
      readAsync = ((url, onload, onerror) => {
        var xhr = new XMLHttpRequest;
        xhr.open('GET', url, true);
        xhr.responseType = 'arraybuffer';
        xhr.onload = (() => {
          if (xhr.status == 200 || xhr.status == 0 && xhr.response) {
            onload(xhr.response);
            return
          }
          onerror()
        });
        xhr.onerror = onerror;
        xhr.send(null)
      })
    }
    setWindowTitle = (title => document.title = title)
  } else {
  }
  var out = Module['print'] || console.log.bind(console);
  var err = Module['printErr'] || console.warn.bind(console);
  Object.assign(Module, moduleOverrides);
  moduleOverrides = null;
  if (Module['arguments']) arguments_ = Module['arguments'];
  if (Module['thisProgram']) thisProgram = Module['thisProgram'];
  if (Module['quit']) quit_ = Module['quit'];
  var tempRet0 = 0;
  var setTempRet0 = value => {
    tempRet0 = value
  };
  var getTempRet0 = () => tempRet0;
  var wasmBinary;
  if (Module['wasmBinary']) wasmBinary = Module['wasmBinary'];
  var noExitRuntime = Module['noExitRuntime'] || true;
  if (typeof WebAssembly != 'object') {
    abort('no native wasm support detected')
  }
  var wasmMemory;
  var ABORT = false;
  var EXITSTATUS;
  var UTF8Decoder = typeof TextDecoder != 'undefined' ? new TextDecoder('utf8') : undefined;
  function UTF8ArrayToString(heap, idx, maxBytesToRead) {
    var endIdx = idx + maxBytesToRead;
    var endPtr = idx;
    while (heap[endPtr] && !(endPtr >= endIdx)) ++endPtr;
    if (endPtr - idx > 16 && heap.subarray && UTF8Decoder) {
      return UTF8Decoder.decode(heap.subarray(idx, endPtr))
    } else {
      var str = '';
      while (idx < endPtr) {
        var u0 = heap[idx++];
        if (!(u0 & 128)) {
          str += String.fromCharCode(u0);
          continue
        }
        var u1 = heap[idx++] & 63;
        if ((u0 & 224) == 192) {
          str += String.fromCharCode((u0 & 31) << 6 | u1);
          continue
        }
        var u2 = heap[idx++] & 63;
        if ((u0 & 240) == 224) {
          u0 = (u0 & 15) << 12 | u1 << 6 | u2
        } else {
          u0 = (u0 & 7) << 18 | u1 << 12 | u2 << 6 | heap[idx++] & 63
        }
        if (u0 < 65536) {
          str += String.fromCharCode(u0)
        } else {
          var ch = u0 - 65536;
          str += String.fromCharCode(55296 | ch >> 10, 56320 | ch & 1023)
        }
      }
    }
    return str
  }
  function UTF8ToString(ptr, maxBytesToRead) {
    return ptr ? UTF8ArrayToString(HEAPU8, ptr, maxBytesToRead) : ''
  }
  var buffer, HEAP8, HEAPU8, HEAP16, HEAPU16, HEAP32, HEAPU32, HEAPF32, HEAPF64;
  function updateGlobalBufferAndViews(buf) {
    buffer = buf;
    Module['HEAP8'] = HEAP8 = new Int8Array(buf);
    Module['HEAP16'] = HEAP16 = new Int16Array(buf);
    Module['HEAP32'] = HEAP32 = new Int32Array(buf);
    Module['HEAPU8'] = HEAPU8 = new Uint8Array(buf);
    Module['HEAPU16'] = HEAPU16 = new Uint16Array(buf);
    Module['HEAPU32'] = HEAPU32 = new Uint32Array(buf);
    Module['HEAPF32'] = HEAPF32 = new Float32Array(buf);
    Module['HEAPF64'] = HEAPF64 = new Float64Array(buf)
  }
  var INITIAL_MEMORY = Module['INITIAL_MEMORY'] || 16777216;
  var wasmTable;
  var __ATPRERUN__ = [];
  var __ATINIT__ = [];
  var __ATPOSTRUN__ = [];
  var runtimeInitialized = false;
  function preRun() {
    if (Module['preRun']) {
      if (typeof Module['preRun'] == 'function') Module['preRun'] = [Module['preRun']];
      while (Module['preRun'].length) {
        addOnPreRun(Module['preRun'].shift())
      }
    }
    callRuntimeCallbacks(__ATPRERUN__)
  }
  function initRuntime() {
    runtimeInitialized = true;
    callRuntimeCallbacks(__ATINIT__)
  }
  function postRun() {
    if (Module['postRun']) {
      if (typeof Module['postRun'] == 'function') Module['postRun'] = [Module['postRun']];
      while (Module['postRun'].length) {
        addOnPostRun(Module['postRun'].shift())
      }
    }
    callRuntimeCallbacks(__ATPOSTRUN__)
  }
  function addOnPreRun(cb) { __ATPRERUN__.unshift(cb) }
  function addOnInit(cb) { __ATINIT__.unshift(cb) }
  function addOnPostRun(cb) { __ATPOSTRUN__.unshift(cb) }
  var runDependencies = 0;
  var runDependencyWatcher = null;
  var dependenciesFulfilled = null;
  function addRunDependency(id) {
    runDependencies++;
    if (Module['monitorRunDependencies']) {
      Module['monitorRunDependencies'](runDependencies)
    }
  }
  function removeRunDependency(id) {
    runDependencies--;
    if (Module['monitorRunDependencies']) {
      Module['monitorRunDependencies'](runDependencies)
    }
    if (runDependencies == 0) {
      if (runDependencyWatcher !== null) {
        clearInterval(runDependencyWatcher);
        runDependencyWatcher = null
      }
      if (dependenciesFulfilled) {
        var callback = dependenciesFulfilled;
        dependenciesFulfilled = null;
        callback()
      }
    }
  }
  Module['preloadedImages'] = {};
  Module['preloadedAudios'] = {};
  function abort(what) {
    {
      if (Module['onAbort']) {
        Module['onAbort'](what)
      }
    }
    what = 'Aborted(' + what + ')';
    err(what);
    ABORT = true;
    EXITSTATUS = 1;
    what += '. Build with -s ASSERTIONS=1 for more info.';
    var e = new WebAssembly.RuntimeError(what);
    readyPromiseReject(e);
    throw e
  }
  var dataURIPrefix = 'data:application/octet-stream;base64,';
  function isDataURI(filename) { return filename.startsWith(dataURIPrefix) }
  var wasmBinaryFile;
  if (Module['locateFile']) {
    wasmBinaryFile = 'geomip-core.wasm';
    if (!isDataURI(wasmBinaryFile)) {
      wasmBinaryFile = locateFile(wasmBinaryFile)
    }
  } else {
    wasmBinaryFile = new URL('geomip-core.wasm', import.meta.url).toString()
  }
  function getBinary(file) {
    try {
      if (file == wasmBinaryFile && wasmBinary) {
        return new Uint8Array(wasmBinary)
      }
      if (readBinary) {
        return readBinary(file)
      } else {
        throw 'both async and sync fetching of the wasm failed'
      }
    } catch (err) {
      abort(err)
    }
  }
  function getBinaryPromise() {
    if (!wasmBinary && (ENVIRONMENT_IS_WEB || ENVIRONMENT_IS_WORKER)) {
      if (typeof fetch == 'function') {
        return fetch(wasmBinaryFile, {credentials: 'same-origin'})
            .then(function(response) {
              if (!response['ok']) {
                throw 'failed to load wasm binary file at \'' + wasmBinaryFile + '\''
              }
              return response['arrayBuffer']()
            })
            .catch(function() { return getBinary(wasmBinaryFile) })
      }
    }
    return Promise.resolve().then(function() { return getBinary(wasmBinaryFile) })
  }
  function createWasm() {
    var info = {'a': asmLibraryArg};
    function receiveInstance(instance, module) {
      var exports = instance.exports;
      Module['asm'] = exports;
      wasmMemory = Module['asm']['J'];
      updateGlobalBufferAndViews(wasmMemory.buffer);
      wasmTable = Module['asm']['L'];
      addOnInit(Module['asm']['K']);
      removeRunDependency('wasm-instantiate')
    }
    addRunDependency('wasm-instantiate');
    function receiveInstantiationResult(result) { receiveInstance(result['instance']) }
    function instantiateArrayBuffer(receiver) {
      return getBinaryPromise()
          .then(function(binary) { return WebAssembly.instantiate(binary, info) })
          .then(function(instance) { return instance })
          .then(receiver, function(reason) {
            err('failed to asynchronously prepare wasm: ' + reason);
            abort(reason)
          })
    }
    function instantiateAsync() {
      if (!wasmBinary && typeof WebAssembly.instantiateStreaming == 'function' &&
          !isDataURI(wasmBinaryFile) && typeof fetch == 'function') {
        return fetch(wasmBinaryFile, {credentials: 'same-origin'}).then(function(response) {
          var result = WebAssembly.instantiateStreaming(response, info);
          return result.then(receiveInstantiationResult, function(reason) {
            err('wasm streaming compile failed: ' + reason);
            err('falling back to ArrayBuffer instantiation');
            return instantiateArrayBuffer(receiveInstantiationResult)
          })
        })
      } else {
        return instantiateArrayBuffer(receiveInstantiationResult)
      }
    }
    if (Module['instantiateWasm']) {
      try {
        var exports = Module['instantiateWasm'](info, receiveInstance);
        return exports
      } catch (e) {
        err('Module.instantiateWasm callback failed with error: ' + e);
        return false
      }
    }
    instantiateAsync().catch(readyPromiseReject);
    return {}
  }
  function callRuntimeCallbacks(callbacks) {
    while (callbacks.length > 0) {
      var callback = callbacks.shift();
      if (typeof callback == 'function') {
        callback(Module);
        continue
      }
      var func = callback.func;
      if (typeof func == 'number') {
        if (callback.arg === undefined) {
          getWasmTableEntry(func)()
        } else {
          getWasmTableEntry(func)(callback.arg)
        }
      } else {
        func(callback.arg === undefined ? null : callback.arg)
      }
    }
  }
  var wasmTableMirror = [];
  function getWasmTableEntry(funcPtr) {
    var func = wasmTableMirror[funcPtr];
    if (!func) {
      if (funcPtr >= wasmTableMirror.length) wasmTableMirror.length = funcPtr + 1;
      wasmTableMirror[funcPtr] = func = wasmTable.get(funcPtr)
    }
    return func
  }
  function ___cxa_allocate_exception(size) { return _malloc(size + 16) + 16 }
  function ExceptionInfo(excPtr) {
    this.excPtr = excPtr;
    this.ptr = excPtr - 16;
    this.set_type = function(type) { HEAP32[this.ptr + 4 >> 2] = type };
    this.get_type = function() { return HEAP32[this.ptr + 4 >> 2] };
    this.set_destructor = function(destructor) { HEAP32[this.ptr + 8 >> 2] = destructor };
    this.get_destructor = function() { return HEAP32[this.ptr + 8 >> 2] };
    this.set_refcount = function(refcount) { HEAP32[this.ptr >> 2] = refcount };
    this.set_caught = function(caught) {
      caught = caught ? 1 : 0;
      HEAP8[this.ptr + 12 >> 0] = caught
    };
    this.get_caught = function() { return HEAP8[this.ptr + 12 >> 0] != 0 };
    this.set_rethrown = function(rethrown) {
      rethrown = rethrown ? 1 : 0;
      HEAP8[this.ptr + 13 >> 0] = rethrown
    };
    this.get_rethrown = function() { return HEAP8[this.ptr + 13 >> 0] != 0 };
    this.init = function(type, destructor) {
      this.set_type(type);
      this.set_destructor(destructor);
      this.set_refcount(0);
      this.set_caught(false);
      this.set_rethrown(false)
    };
    this.add_ref = function() {
      var value = HEAP32[this.ptr >> 2];
      HEAP32[this.ptr >> 2] = value + 1
    };
    this.release_ref = function() {
      var prev = HEAP32[this.ptr >> 2];
      HEAP32[this.ptr >> 2] = prev - 1;
      return prev === 1
    }
  }
  function CatchInfo(ptr) {
    this.free = function() {
      _free(this.ptr);
      this.ptr = 0
    };
    this.set_base_ptr = function(basePtr) { HEAP32[this.ptr >> 2] = basePtr };
    this.get_base_ptr = function() { return HEAP32[this.ptr >> 2] };
    this.set_adjusted_ptr = function(adjustedPtr) { HEAP32[this.ptr + 4 >> 2] = adjustedPtr };
    this.get_adjusted_ptr_addr = function() { return this.ptr + 4 };
    this.get_adjusted_ptr = function() { return HEAP32[this.ptr + 4 >> 2] };
    this.get_exception_ptr = function() {
      var isPointer = ___cxa_is_pointer_type(this.get_exception_info().get_type());
      if (isPointer) {
        return HEAP32[this.get_base_ptr() >> 2]
      }
      var adjusted = this.get_adjusted_ptr();
      if (adjusted !== 0) return adjusted;
      return this.get_base_ptr()
    };
    this.get_exception_info = function() { return new ExceptionInfo(this.get_base_ptr()) };
    if (ptr === undefined) {
      this.ptr = _malloc(8);
      this.set_adjusted_ptr(0)
    } else {
      this.ptr = ptr
    }
  }
  var exceptionCaught = [];
  function exception_addRef(info) { info.add_ref() }
  var uncaughtExceptionCount = 0;
  function ___cxa_begin_catch(ptr) {
    var catchInfo = new CatchInfo(ptr);
    var info = catchInfo.get_exception_info();
    if (!info.get_caught()) {
      info.set_caught(true);
      uncaughtExceptionCount--
    }
    info.set_rethrown(false);
    exceptionCaught.push(catchInfo);
    exception_addRef(info);
    return catchInfo.get_exception_ptr()
  }
  function ___cxa_current_primary_exception() {
    if (!exceptionCaught.length) {
      return 0
    }
    var catchInfo = exceptionCaught[exceptionCaught.length - 1];
    exception_addRef(catchInfo.get_exception_info());
    return catchInfo.get_base_ptr()
  }
  function ___cxa_free_exception(ptr) { return _free(new ExceptionInfo(ptr).ptr) }
  function exception_decRef(info) {
    if (info.release_ref() && !info.get_rethrown()) {
      var destructor = info.get_destructor();
      if (destructor) {
        getWasmTableEntry(destructor)(info.excPtr)
      }
      ___cxa_free_exception(info.excPtr)
    }
  }
  function ___cxa_decrement_exception_refcount(ptr) {
    if (!ptr) return;
    exception_decRef(new ExceptionInfo(ptr))
  }
  var exceptionLast = 0;
  function ___cxa_end_catch() {
    _setThrew(0);
    var catchInfo = exceptionCaught.pop();
    exception_decRef(catchInfo.get_exception_info());
    catchInfo.free();
    exceptionLast = 0
  }
  function ___resumeException(catchInfoPtr) {
    var catchInfo = new CatchInfo(catchInfoPtr);
    var ptr = catchInfo.get_base_ptr();
    if (!exceptionLast) {
      exceptionLast = ptr
    }
    catchInfo.free();
    throw ptr
  }
  function ___cxa_find_matching_catch_2() {
    var thrown = exceptionLast;
    if (!thrown) {
      setTempRet0(0);
      return 0 | 0
    }
    var info = new ExceptionInfo(thrown);
    var thrownType = info.get_type();
    var catchInfo = new CatchInfo;
    catchInfo.set_base_ptr(thrown);
    catchInfo.set_adjusted_ptr(thrown);
    if (!thrownType) {
      setTempRet0(0);
      return catchInfo.ptr | 0
    }
    var typeArray = Array.prototype.slice.call(arguments);
    for (var i = 0; i < typeArray.length; i++) {
      var caughtType = typeArray[i];
      if (caughtType === 0 || caughtType === thrownType) {
        break
      }
      if (___cxa_can_catch(caughtType, thrownType, catchInfo.get_adjusted_ptr_addr())) {
        setTempRet0(caughtType);
        return catchInfo.ptr | 0
      }
    }
    setTempRet0(thrownType);
    return catchInfo.ptr | 0
  }
  function ___cxa_find_matching_catch_3() {
    var thrown = exceptionLast;
    if (!thrown) {
      setTempRet0(0);
      return 0 | 0
    }
    var info = new ExceptionInfo(thrown);
    var thrownType = info.get_type();
    var catchInfo = new CatchInfo;
    catchInfo.set_base_ptr(thrown);
    catchInfo.set_adjusted_ptr(thrown);
    if (!thrownType) {
      setTempRet0(0);
      return catchInfo.ptr | 0
    }
    var typeArray = Array.prototype.slice.call(arguments);
    for (var i = 0; i < typeArray.length; i++) {
      var caughtType = typeArray[i];
      if (caughtType === 0 || caughtType === thrownType) {
        break
      }
      if (___cxa_can_catch(caughtType, thrownType, catchInfo.get_adjusted_ptr_addr())) {
        setTempRet0(caughtType);
        return catchInfo.ptr | 0
      }
    }
    setTempRet0(thrownType);
    return catchInfo.ptr | 0
  }
  function ___cxa_find_matching_catch_4() {
    var thrown = exceptionLast;
    if (!thrown) {
      setTempRet0(0);
      return 0 | 0
    }
    var info = new ExceptionInfo(thrown);
    var thrownType = info.get_type();
    var catchInfo = new CatchInfo;
    catchInfo.set_base_ptr(thrown);
    catchInfo.set_adjusted_ptr(thrown);
    if (!thrownType) {
      setTempRet0(0);
      return catchInfo.ptr | 0
    }
    var typeArray = Array.prototype.slice.call(arguments);
    for (var i = 0; i < typeArray.length; i++) {
      var caughtType = typeArray[i];
      if (caughtType === 0 || caughtType === thrownType) {
        break
      }
      if (___cxa_can_catch(caughtType, thrownType, catchInfo.get_adjusted_ptr_addr())) {
        setTempRet0(caughtType);
        return catchInfo.ptr | 0
      }
    }
    setTempRet0(thrownType);
    return catchInfo.ptr | 0
  }
  function ___cxa_increment_exception_refcount(ptr) {
    if (!ptr) return;
    exception_addRef(new ExceptionInfo(ptr))
  }
  function ___cxa_rethrow() {
    var catchInfo = exceptionCaught.pop();
    if (!catchInfo) {
      abort('no exception to throw')
    }
    var info = catchInfo.get_exception_info();
    var ptr = catchInfo.get_base_ptr();
    if (!info.get_rethrown()) {
      exceptionCaught.push(catchInfo);
      info.set_rethrown(true);
      info.set_caught(false);
      uncaughtExceptionCount++
    } else {
      catchInfo.free()
    }
    exceptionLast = ptr;
    throw ptr
  }
  function ___cxa_rethrow_primary_exception(ptr) {
    if (!ptr) return;
    var catchInfo = new CatchInfo;
    catchInfo.set_base_ptr(ptr);
    var info = catchInfo.get_exception_info();
    exceptionCaught.push(catchInfo);
    info.set_rethrown(true);
    ___cxa_rethrow()
  }
  function ___cxa_throw(ptr, type, destructor) {
    var info = new ExceptionInfo(ptr);
    info.init(type, destructor);
    exceptionLast = ptr;
    uncaughtExceptionCount++;
    throw ptr
  }
  function _abort() { abort('') }
  function _emscripten_get_heap_max() { return 2147483648 }
  function _emscripten_memcpy_big(dest, src, num) { HEAPU8.copyWithin(dest, src, src + num) }
  function emscripten_realloc_buffer(size) {
    try {
      wasmMemory.grow(size - buffer.byteLength + 65535 >>> 16);
      updateGlobalBufferAndViews(wasmMemory.buffer);
      return 1
    } catch (e) {
    }
  }
  function _emscripten_resize_heap(requestedSize) {
    var oldSize = HEAPU8.length;
    requestedSize = requestedSize >>> 0;
    var maxHeapSize = _emscripten_get_heap_max();
    if (requestedSize > maxHeapSize) {
      return false
    }
    let alignUp = (x, multiple) => x + (multiple - x % multiple) % multiple;
    for (var cutDown = 1; cutDown <= 4; cutDown *= 2) {
      var overGrownHeapSize = oldSize * (1 + .2 / cutDown);
      overGrownHeapSize = Math.min(overGrownHeapSize, requestedSize + 100663296);
      var newSize = Math.min(maxHeapSize, alignUp(Math.max(requestedSize, overGrownHeapSize), 65536));
      var replacement = emscripten_realloc_buffer(newSize);
      if (replacement) {
        return true
      }
    }
    return false
  }
  function _getTempRet0() { return getTempRet0() }
  function _llvm_eh_typeid_for(type) { return type }
  var asmLibraryArg = {
    'j': ___cxa_allocate_exception,
    'k': ___cxa_begin_catch,
    'E': ___cxa_current_primary_exception,
    'y': ___cxa_decrement_exception_refcount,
    'o': ___cxa_end_catch,
    'b': ___cxa_find_matching_catch_2,
    'f': ___cxa_find_matching_catch_3,
    'w': ___cxa_find_matching_catch_4,
    'u': ___cxa_free_exception,
    'x': ___cxa_increment_exception_refcount,
    'D': ___cxa_rethrow_primary_exception,
    'n': ___cxa_throw,
    'd': ___resumeException,
    'v': _abort,
    'C': _emscripten_get_heap_max,
    'G': _emscripten_memcpy_big,
    'F': _emscripten_resize_heap,
    'a': _getTempRet0,
    't': invoke_i,
    'e': invoke_ii,
    'i': invoke_iii,
    'm': invoke_iiii,
    'r': invoke_iiiii,
    'I': invoke_iiiiiii,
    'l': invoke_v,
    'c': invoke_vi,
    'g': invoke_vii,
    'h': invoke_viii,
    's': invoke_viiii,
    'z': invoke_viiiii,
    'q': invoke_viiiiii,
    'H': invoke_viiiiiiiiiidii,
    'A': invoke_viiij,
    'B': invoke_vij,
    'p': _llvm_eh_typeid_for
  };
  var asm = createWasm();
  var ___wasm_call_ctors = Module['___wasm_call_ctors'] = function() {
    return (___wasm_call_ctors = Module['___wasm_call_ctors'] = Module['asm']['K']).apply(null, arguments)
  };
  var _gip_create = Module['_gip_create'] =
      function() { return (_gip_create = Module['_gip_create'] = Module['asm']['M']).apply(null, arguments) };
  var _gip_destroy = Module['_gip_destroy'] = function() {
    return (_gip_destroy = Module['_gip_destroy'] = Module['asm']['N']).apply(null, arguments)
  };
  var _gip_reserve = Module['_gip_reserve'] = function() {
    return (_gip_reserve = Module['_gip_reserve'] = Module['asm']['O']).apply(null, arguments)
  };
  var _gip_commit = Module['_gip_commit'] =
      function() { return (_gip_commit = Module['_gip_commit'] = Module['asm']['P']).apply(null, arguments) };
  var _gip_size = Module['_gip_size'] =
      function() { return (_gip_size = Module['_gip_size'] = Module['asm']['Q']).apply(null, arguments) };
  var _gip_status_message = Module['_gip_status_message'] = function() {
    return (_gip_status_message = Module['_gip_status_message'] = Module['asm']['R']).apply(null, arguments)
  };
  var _gip_read_info = Module['_gip_read_info'] = function() {
    return (_gip_read_info = Module['_gip_read_info'] = Module['asm']['S']).apply(null, arguments)
  };
  var _gip_needed = Module['_gip_needed'] =
      function() { return (_gip_needed = Module['_gip_needed'] = Module['asm']['T']).apply(null, arguments) };
  var _gip_manifest_end = Module['_gip_manifest_end'] = function() {
    return (_gip_manifest_end = Module['_gip_manifest_end'] = Module['asm']['U']).apply(null, arguments)
  };
  var _gip_file_size = Module['_gip_file_size'] = function() {
    return (_gip_file_size = Module['_gip_file_size'] = Module['asm']['V']).apply(null, arguments)
  };
  var _gip_num_chunks = Module['_gip_num_chunks'] = function() {
    return (_gip_num_chunks = Module['_gip_num_chunks'] = Module['asm']['W']).apply(null, arguments)
  };
  var _gip_chunk = Module['_gip_chunk'] =
      function() { return (_gip_chunk = Module['_gip_chunk'] = Module['asm']['X']).apply(null, arguments) };
  var _gip_decode = Module['_gip_decode'] =
      function() { return (_gip_decode = Module['_gip_decode'] = Module['asm']['Y']).apply(null, arguments) };
  var _gip_bytes_used = Module['_gip_bytes_used'] = function() {
    return (_gip_bytes_used = Module['_gip_bytes_used'] = Module['asm']['Z']).apply(null, arguments)
  };
  var _gip_chunks_decoded = Module['_gip_chunks_decoded'] = function() {
    return (_gip_chunks_decoded = Module['_gip_chunks_decoded'] = Module['asm']['_']).apply(null, arguments)
  };
  var _gip_num_models = Module['_gip_num_models'] = function() {
    return (_gip_num_models = Module['_gip_num_models'] = Module['asm']['$']).apply(null, arguments)
  };
  var _gip_model_name = Module['_gip_model_name'] = function() {
    return (_gip_model_name = Module['_gip_model_name'] = Module['asm']['aa']).apply(null, arguments)
  };
  var _gip_model_normalization = Module['_gip_model_normalization'] = function() {
    return (_gip_model_normalization = Module['_gip_model_normalization'] = Module['asm']['ba'])
        .apply(null, arguments)
  };
  var _gip_model_field = Module['_gip_model_field'] = function() {
    return (_gip_model_field = Module['_gip_model_field'] = Module['asm']['ca']).apply(null, arguments)
  };
  var _gip_grid = Module['_gip_grid'] =
      function() { return (_gip_grid = Module['_gip_grid'] = Module['asm']['da']).apply(null, arguments) };
  var _gip_hole_mask = Module['_gip_hole_mask'] = function() {
    return (_gip_hole_mask = Module['_gip_hole_mask'] = Module['asm']['ea']).apply(null, arguments)
  };
  var _gip_decode_scene = Module['_gip_decode_scene'] = function() {
    return (_gip_decode_scene = Module['_gip_decode_scene'] = Module['asm']['fa']).apply(null, arguments)
  };
  var _gip_scene_bytes_used = Module['_gip_scene_bytes_used'] = function() {
    return (_gip_scene_bytes_used = Module['_gip_scene_bytes_used'] = Module['asm']['ga'])
        .apply(null, arguments)
  };
  var _gip_scene_count = Module['_gip_scene_count'] = function() {
    return (_gip_scene_count = Module['_gip_scene_count'] = Module['asm']['ha']).apply(null, arguments)
  };
  var _gip_scene_name = Module['_gip_scene_name'] = function() {
    return (_gip_scene_name = Module['_gip_scene_name'] = Module['asm']['ia']).apply(null, arguments)
  };
  var _gip_scene_field = Module['_gip_scene_field'] = function() {
    return (_gip_scene_field = Module['_gip_scene_field'] = Module['asm']['ja']).apply(null, arguments)
  };
  var _gip_scene_data = Module['_gip_scene_data'] = function() {
    return (_gip_scene_data = Module['_gip_scene_data'] = Module['asm']['ka']).apply(null, arguments)
  };
  var _free = Module['_free'] =
      function() { return (_free = Module['_free'] = Module['asm']['la']).apply(null, arguments) };
  var _malloc = Module['_malloc'] =
      function() { return (_malloc = Module['_malloc'] = Module['asm']['ma']).apply(null, arguments) };
  var _setThrew = Module['_setThrew'] =
      function() { return (_setThrew = Module['_setThrew'] = Module['asm']['na']).apply(null, arguments) };
  var stackSave = Module['stackSave'] =
      function() { return (stackSave = Module['stackSave'] = Module['asm']['oa']).apply(null, arguments) };
  var stackRestore = Module['stackRestore'] = function() {
    return (stackRestore = Module['stackRestore'] = Module['asm']['pa']).apply(null, arguments)
  };
  var ___cxa_can_catch = Module['___cxa_can_catch'] = function() {
    return (___cxa_can_catch = Module['___cxa_can_catch'] = Module['asm']['qa']).apply(null, arguments)
  };
  var ___cxa_is_pointer_type = Module['___cxa_is_pointer_type'] = function() {
    return (___cxa_is_pointer_type = Module['___cxa_is_pointer_type'] = Module['asm']['ra'])
        .apply(null, arguments)
  };
  var dynCall_vij = Module['dynCall_vij'] = function() {
    return (dynCall_vij = Module['dynCall_vij'] = Module['asm']['sa']).apply(null, arguments)
  };
  var dynCall_viiij = Module['dynCall_viiij'] = function() {
    return (dynCall_viiij = Module['dynCall_viiij'] = Module['asm']['ta']).apply(null, arguments)
  };
  function invoke_iii(index, a1, a2) {
    var sp = stackSave();
    try {
      return getWasmTableEntry(index)(a1, a2)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_vi(index, a1) {
    var sp = stackSave();
    try {
      getWasmTableEntry(index)(a1)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_ii(index, a1) {
    var sp = stackSave();
    try {
      return getWasmTableEntry(index)(a1)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_viii(index, a1, a2, a3) {
    var sp = stackSave();
    try {
      getWasmTableEntry(index)(a1, a2, a3)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_vii(index, a1, a2) {
    var sp = stackSave();
    try {
      getWasmTableEntry(index)(a1, a2)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_iiii(index, a1, a2, a3) {
    var sp = stackSave();
    try {
      return getWasmTableEntry(index)(a1, a2, a3)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_v(index) {
    var sp = stackSave();
    try {
      getWasmTableEntry(index)()
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_viiii(index, a1, a2, a3, a4) {
    var sp = stackSave();
    try {
      getWasmTableEntry(index)(a1, a2, a3, a4)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_iiiii(index, a1, a2, a3, a4) {
    var sp = stackSave();
    try {
      return getWasmTableEntry(index)(a1, a2, a3, a4)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_iiiiiii(index, a1, a2, a3, a4, a5, a6) {
    var sp = stackSave();
    try {
      return getWasmTableEntry(index)(a1, a2, a3, a4, a5, a6)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_i(index) {
    var sp = stackSave();
    try {
      return getWasmTableEntry(index)()
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_viiiiii(index, a1, a2, a3, a4, a5, a6) {
    var sp = stackSave();
    try {
      getWasmTableEntry(index)(a1, a2, a3, a4, a5, a6)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_viiiii(index, a1, a2, a3, a4, a5) {
    var sp = stackSave();
    try {
      getWasmTableEntry(index)(a1, a2, a3, a4, a5)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_viiiiiiiiiidii(index, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10, a11, a12, a13) {
    var sp = stackSave();
    try {
      getWasmTableEntry(index)(a1, a2, a3, a4, a5, a6, a7, a8, a9, a10, a11, a12, a13)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_vij(index, a1, a2, a3) {
    var sp = stackSave();
    try {
      dynCall_vij(index, a1, a2, a3)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  function invoke_viiij(index, a1, a2, a3, a4, a5) {
    var sp = stackSave();
    try {
      dynCall_viiij(index, a1, a2, a3, a4, a5)
    } catch (e) {
      stackRestore(sp);
      if (e !== e + 0) throw e;
      _setThrew(1, 0)
    }
  }
  Module['UTF8ToString'] = UTF8ToString;
  var calledRun;
  dependenciesFulfilled = function runCaller() {
    if (!calledRun) run();
    if (!calledRun) dependenciesFulfilled = runCaller
  };
  function run(args) {
    args = args || arguments_;
    if (runDependencies > 0) {
      return
    }
    preRun();
    if (runDependencies > 0) {
      return
    }
    function doRun() {
      if (calledRun) return;
      calledRun = true;
      Module['calledRun'] = true;
      if (ABORT) return;
      initRuntime();
      readyPromiseResolve(Module);
      if (Module['onRuntimeInitialized']) Module['onRuntimeInitialized']();
      postRun()
    }
    if (Module['setStatus']) {
      Module['setStatus']('Running...');
      setTimeout(function() {
        setTimeout(function() { Module['setStatus']('') }, 1);
        doRun()
      }, 1)
    } else {
      doRun()
    }
  }
  Module['run'] = run;
  if (Module['preInit']) {
    if (typeof Module['preInit'] == 'function') Module['preInit'] = [Module['preInit']];
    while (Module['preInit'].length > 0) {
      Module['preInit'].pop()()
    }
  }
  run();


  return createGeomipCore.ready
}
);
})();
export default createGeomipCore;