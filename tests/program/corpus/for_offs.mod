MODULE ForOffs
    CONST robtarget pRow := [[300, 20, 300], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST num nPitch := 50;
    PROC main()
        FOR k FROM 0 TO 4 DO
            MoveJ Offs(pRow, 0, k * nPitch, 60), v1000, z20, tool0;
            MoveL Offs(pRow, 0, k * nPitch, 0), v200, fine, tool0;
            MoveL Offs(pRow, 0, k * nPitch, 60), v200, z20, tool0;
        ENDFOR
    ENDPROC
ENDMODULE
